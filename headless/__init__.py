"""The ``stealth`` command line, sweeps, the results store and reports (drives ``game``)."""
