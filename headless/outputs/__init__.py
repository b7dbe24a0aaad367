"""Output files: safe names, never one of the inputs, the results-directory lock."""
