"""Played sessions (``stealth play --record``) as trials of a store, and their report."""
