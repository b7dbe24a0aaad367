"""The batched engine: many trials stepped together in compiled loops."""
