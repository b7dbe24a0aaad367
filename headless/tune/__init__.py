"""``stealth tune``: an Optuna study of config values against an objective."""
