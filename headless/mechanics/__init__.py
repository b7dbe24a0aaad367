"""``stealth mechanics``: each mechanic measured against its paired control."""
