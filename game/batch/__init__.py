"""The batch engine (SPEC §12 ``world.engine = "batch"``): many trials of one level and
abstraction in lockstep, equal to the pymunk engine trial for trial (:mod:`.engine`)."""

from .engine import MAX_BATCH, Batch, refusal_text, run_trials, uncovered

__all__ = ["Batch", "MAX_BATCH", "refusal_text", "run_trials", "uncovered"]
