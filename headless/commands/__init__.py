"""The command line's parts beside its parser: the one failure handler every entry point shares, and the level commands."""
