"""The game's sounds: synthesised in code (numpy), played through pygame-ce's mixer.

Every sound is a short buffer made once from sine tones, noise and envelopes (no files,
so no licence to carry). :class:`SoundBoard` turns what happens in a world into sound
events — footsteps (slow walk / walk / sprint, louder on sprints: the steps the guards
hear), a throw and its landing, a decoy switched on, a take-down, a star picked up, each hit
the player takes, an action refused, rain (a loop while it rains), a guard's rising
suspicion, the sting of a sighting, the team's alert phases as a low cue, and the end of a
game — and
counts every event it plays (:attr:`SoundBoard.played`), so a test can check them without
hearing them.

Without an audio device (no sound card, or SDL cannot open one) the board is silent:
:attr:`SoundBoard.available` is False and :meth:`SoundBoard.play` only counts.

>>> wave = synthesise("sighting", 22050)
>>> wave.dtype, 0.1 < len(wave) / 22050 < 1.0, int(abs(wave).max()) <= 32767
(dtype('int16'), True, True)
"""

from __future__ import annotations

import os
import sys
from collections import Counter
from collections.abc import Callable, Mapping

import numpy as np
import pygame

__all__ = ["KINDS", "SoundBoard", "synthesise"]

RATE = 22050


def _t(seconds: float, rate: int) -> np.ndarray:
    return np.arange(int(seconds * rate)) / rate


def _envelope(n: int, attack: float, rate: int) -> np.ndarray:
    """A fast linear attack and an exponential release over ``n`` samples."""
    a = max(1, int(attack * rate))
    env = np.exp(-np.arange(n) / max(1.0, n / 5.0))
    env[:a] *= np.linspace(0.0, 1.0, a)
    return env


def _noise(seconds: float, rate: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-1.0, 1.0, int(seconds * rate))


def _step(rate: int, loud: float, seed: int) -> np.ndarray:
    """A footstep: a low thump with a short scuff of filtered noise."""
    t = _t(0.09, rate)
    thump = np.sin(2 * np.pi * (90 - 300 * t) * t)
    scuff = np.convolve(_noise(0.09, rate, seed), np.ones(6) / 6, mode="same")
    return loud * (0.7 * thump + 0.5 * scuff) * _envelope(len(t), 0.004, rate)


def _tone(rate: int, seconds: float, f0: float, f1: float, attack: float = 0.01) -> np.ndarray:
    t = _t(seconds, rate)
    phase = 2 * np.pi * np.cumsum(np.linspace(f0, f1, len(t))) / rate
    return np.sin(phase) * _envelope(len(t), attack, rate)


def _landing(rate: int) -> np.ndarray:
    """A decoy's clatter: three knocks of bright noise."""
    out = np.zeros(int(0.35 * rate))
    for k, (at, gain) in enumerate(((0.0, 1.0), (0.11, 0.6), (0.2, 0.35))):
        knock = _noise(0.06, rate, 11 + k) * _envelope(int(0.06 * rate), 0.002, rate)
        start = int(at * rate)
        out[start:start + len(knock)] += gain * knock
    return 0.8 * out


def _takedown(rate: int) -> np.ndarray:
    t = _t(0.3, rate)
    body = np.sin(2 * np.pi * (120 - 200 * t) * t) + 0.4 * _noise(0.3, rate, 5)
    return 0.9 * body * _envelope(len(t), 0.003, rate)


def _rain(rate: int) -> np.ndarray:
    """Two seconds of soft noise, looped while it rains."""
    hiss = np.convolve(_noise(2.0, rate, 3), np.ones(3) / 3, mode="same")
    fade = int(0.05 * rate)
    hiss[:fade] *= np.linspace(0, 1, fade)
    hiss[-fade:] *= np.linspace(1, 0, fade)
    return 0.18 * hiss


def _chord(rate: int, seconds: float, freqs: tuple[float, ...], gain: float) -> np.ndarray:
    t = _t(seconds, rate)
    wave = sum(np.sin(2 * np.pi * f * t) for f in freqs) / len(freqs)
    return gain * np.asarray(wave) * _envelope(len(t), 0.05, rate)


#: kind → how its buffer is made (float samples in [-1, 1] at ``rate``)
_MAKERS: dict[str, Callable[[int], np.ndarray]] = {
    "step": lambda r: _step(r, 0.35, 1),
    "step_sprint": lambda r: _step(r, 0.8, 2),
    "step_quiet": lambda r: _step(r, 0.12, 4),
    "throw": lambda r: 0.35 * _tone(r, 0.18, 300.0, 900.0, 0.02),
    "decoy_on": lambda r: np.concatenate([0.4 * _tone(r, 0.09, 1000.0, 1000.0, 0.004),
                                          np.zeros(int(0.05 * r)),
                                          0.4 * _tone(r, 0.09, 1000.0, 1000.0, 0.004)]),
    "pickup": lambda r: np.concatenate([0.45 * _tone(r, 0.1, 988.0, 988.0, 0.004),
                                        0.45 * _tone(r, 0.2, 1319.0, 1319.0, 0.004)]),
    "hurt": lambda r: 0.7 * _tone(r, 0.2, 180.0, 90.0, 0.002) + 0.2 * _noise(0.2, r, 7)
    * _envelope(int(0.2 * r), 0.002, r),
    "denied": lambda r: 0.3 * _tone(r, 0.15, 220.0, 200.0),
    "decoy_landed": _landing,
    "takedown": _takedown,
    "rain": _rain,
    "suspicion": lambda r: 0.35 * _tone(r, 0.25, 440.0, 660.0),
    "sighting": lambda r: 0.6 * (_tone(r, 0.35, 880.0, 880.0, 0.002)
                                 + _tone(r, 0.35, 1320.0, 1250.0, 0.002)),
    "phase": lambda r: _chord(r, 1.2, (110.0, 164.8), 0.4),
    "win": lambda r: np.concatenate([0.5 * _tone(r, 0.18, f, f) for f in (523.3, 659.3, 784.0)]),
    "lose": lambda r: np.concatenate([0.5 * _tone(r, 0.25, f, f * 0.97) for f in (392.0, 311.1, 233.1)]),
}

#: every sound event kind, in a stable order
KINDS: tuple[str, ...] = tuple(_MAKERS)


def synthesise(kind: str, rate: int = RATE) -> np.ndarray:
    """The sound ``kind`` as mono int16 samples at ``rate`` Hz."""
    wave = np.clip(_MAKERS[kind](rate), -1.0, 1.0)
    return (wave * 32767).astype(np.int16)


#: metres between two footsteps, walking and sprinting
STRIDE = 0.7
SPRINT_STRIDE = 0.9
#: awareness (fraction of the detection threshold) at which a guard's suspicion sounds
SUSPICION_LEVELS = (0.3, 0.6)
#: game seconds between two ``hurt`` sounds while the player keeps being hit
HURT_REPEAT = 0.5


class SoundBoard:
    """The sounds of one game window; silent, but counting, without an audio device.

    ``volume`` is in [0, 1]; :meth:`toggle_mute` and :meth:`change_volume` are the keys'.
    """

    def __init__(self, volume: float = 0.6) -> None:
        self.volume = volume
        self.muted = False
        self.played: Counter[str] = Counter()
        self.available = _open_mixer()
        self._sounds: dict[str, pygame.mixer.Sound] = {}
        if self.available:
            self._sounds = {kind: _make_sound(kind) for kind in KINDS}
        self._rain_channel: pygame.mixer.Channel | None = None
        self._raining = False
        self.reset()

    def reset(self) -> None:
        """Forget the last world (a restart): footsteps, sightings and phases start afresh."""
        self._walked = 0.0
        self._last_pos: tuple[float, float] | None = None
        self._seen_events: object = None
        self._detected = False
        self._phase = ""
        self._suspicion: dict[int, int] = {}
        self._active: int | None = None
        self._damage = 0
        self._hurt_at = -HURT_REPEAT
        self._set_rain(False)

    # ------------------------------------------------------------------ keys
    def toggle_mute(self) -> bool:
        """Mute or unmute everything; returns whether it is muted now."""
        self.muted = not self.muted
        if self.available:
            for sound in self._sounds.values():
                sound.set_volume(0.0 if self.muted else self.volume)
        return self.muted

    def change_volume(self, step: float) -> float:
        """Raise (or lower, ``step < 0``) the volume, kept in [0, 1]; returns it."""
        self.volume = round(min(1.0, max(0.0, self.volume + step)), 2)
        if self.available and not self.muted:
            for sound in self._sounds.values():
                sound.set_volume(self.volume)
        return self.volume

    # ------------------------------------------------------------------ events
    def play(self, kind: str) -> None:
        """Count the event and, with a device and not muted, play its sound."""
        self.played[kind] += 1
        if self.available and not self.muted:
            sound = self._sounds[kind]
            sound.set_volume(self.volume)
            sound.play()

    def observe(self, world: object, detected: bool, phase: str,
                awareness: list[float | None]) -> None:
        """The sound events of the frame just stepped: footsteps from the player's path,
        landings and take-downs from the AI tick's events, rain, a guard's suspicion
        rising through :data:`SUSPICION_LEVELS`, a new sighting and a new alert phase."""
        player = getattr(world, "player")
        x, y = player.pos
        if self._last_pos is not None:
            self._walked += float(np.hypot(x - self._last_pos[0], y - self._last_pos[1]))
        self._last_pos = (x, y)
        sprinting = bool(getattr(world, "sprinting", False))
        stride = SPRINT_STRIDE if sprinting else STRIDE
        if self._walked >= stride:
            self._walked %= stride
            self.play("step_sprint" if sprinting else
                      "step_quiet" if getattr(world, "sneaking", False) else "step")
        events = getattr(world, "tick_events")
        if events is not self._seen_events:
            self._seen_events = events
            for event in events:
                if event.kind == "throw_landed":
                    self.play("decoy_landed")
        # a take-down the moment a guard goes down (its event waits for the AI tick)
        active = sum(1 for g in getattr(world, "guards") if g.active)
        if self._active is not None and active < self._active:
            self.play("takedown")
        self._active = active
        # each hit: the damage grew since the last frame (at most every HURT_REPEAT s)
        damage = int(getattr(world, "health").damage_steps)
        t = float(getattr(world, "t"))
        if damage > self._damage and t - self._hurt_at >= HURT_REPEAT:
            self.play("hurt")
            self._hurt_at = t
        self._damage = damage
        self._set_rain(bool(getattr(world, "raining", False)))
        for i, level in enumerate(awareness):
            reached = sum(level is not None and level >= mark for mark in SUSPICION_LEVELS)
            if reached > self._suspicion.get(i, 0) and not detected:
                self.play("suspicion")
            self._suspicion[i] = reached
        if detected and not self._detected:
            self.play("sighting")
        self._detected = detected
        if phase != self._phase:
            if phase in ("alert", "search", "caution"):
                self.play("phase")
            self._phase = phase

    def game_over(self, outcome: str) -> None:
        """The end of a game: a rising arpeggio when won or survived, a falling one when not."""
        self._set_rain(False)
        self.play("win" if outcome in ("won", "survived") else "lose")

    def _set_rain(self, raining: bool) -> None:
        """Start the rain loop when it starts raining (one ``rain`` event), stop it after."""
        if raining and not self._raining:
            self.played["rain"] += 1
            if self.available and not self.muted:
                self._rain_channel = self._sounds["rain"].play(loops=-1)
        elif not raining and self._rain_channel is not None:
            self._rain_channel.stop()
            self._rain_channel = None
        self._raining = raining

    def close(self) -> None:
        """Stop every sound (the window closes)."""
        if self.available:
            pygame.mixer.stop()


def _open_mixer() -> bool:
    """Open the audio device once; False (silence) when there is none."""
    if pygame.mixer.get_init():
        return True
    if not audio_device_likely():
        return False  # else ALSA prints a dozen lines of its own before SDL gives up
    try:
        pygame.mixer.init(frequency=RATE, size=-16, channels=1, buffer=512)
    except pygame.error:
        return False
    return bool(pygame.mixer.get_init())


def audio_device_likely(environ: Mapping[str, str] | None = None,
                        exists: Callable[[str], bool] = os.path.exists) -> bool:
    """Whether SDL may find an audio device: always, unless on Linux with no driver asked
    for (``SDL_AUDIODRIVER``), no sound card (``/dev/snd``) and no sound server's socket
    (PulseAudio, PipeWire; ``PULSE_SERVER``) — then opening one only fills the terminal."""
    environ = os.environ if environ is None else environ
    if not sys.platform.startswith("linux") or environ.get("SDL_AUDIODRIVER") \
            or environ.get("PULSE_SERVER"):
        return True
    runtime = environ.get("XDG_RUNTIME_DIR", "")
    servers = [f"{runtime}/pulse/native", f"{runtime}/pipewire-0"] if runtime else []
    return any(exists(path) for path in ["/dev/snd", *servers])


def _make_sound(kind: str) -> pygame.mixer.Sound:
    """The kind's buffer in the format the mixer opened with (rate and channels)."""
    init = pygame.mixer.get_init()
    assert init is not None
    rate, _, channels = init
    wave = synthesise(kind, rate)
    if channels > 1:
        wave = np.repeat(wave[:, None], channels, axis=1)
    return pygame.mixer.Sound(buffer=np.ascontiguousarray(wave).tobytes())
