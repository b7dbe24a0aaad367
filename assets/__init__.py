"""The bundled levels as package data (installed as ``stealthfield_assets``).

A regular package, not a namespace one: an editable install elsewhere on the path must not
merge its folder into the installed copy's (``importlib.resources`` refuses such a mix).
"""
