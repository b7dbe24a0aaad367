"""The player's health: damage in whole guard-steps, so HP never drifts with float sums.

A guard in attack range at the start of a physics step hurts the player over the whole
step; with ``hp_max`` HP and step ``dt`` the player dies after ``round(hp_max / dt)``
guard-steps, i.e. at exactly t0 + hp_max seconds in range of one guard.

>>> health = Health(3.0, 0.05)
>>> [health.hurt(1) for _ in range(59)][-1], health.hurt(1), health.hp
(False, True, 0.0)
"""

from __future__ import annotations


class Health:
    """HP of the player of one world."""

    def __init__(self, hp_max: float, dt: float) -> None:
        self.hp_max, self.dt = float(hp_max), float(dt)
        self.damage_steps = 0
        self.lethal_steps = round(self.hp_max / self.dt)

    @property
    def hp(self) -> float:
        """HP left."""
        return self.hp_max - self.damage_steps * self.dt

    def hurt(self, guards: int) -> bool:
        """``guards`` guards hurt the player for one step; True when that was lethal."""
        lethal = self.lethal(guards)
        self.damage_steps += guards
        return lethal

    def lethal(self, guards: int) -> bool:
        """Whether ``guards`` guards hurting the player for one step would be lethal."""
        return self.damage_steps + guards >= self.lethal_steps

    def heal(self) -> None:
        """Full HP again (a respawn)."""
        self.damage_steps = 0


__all__ = ["Health"]
