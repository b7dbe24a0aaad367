"""What is read from a results store: the report, its tables and figures, and the analyses beside it."""
