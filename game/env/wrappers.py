"""The player's observation as a dict or an image, and MiniGrid-style wrappers between them.

``StealthEnv(observation="flat")`` (the default) gives the flat vector of docs/api.md;
``"dict"`` the same numbers as ``{"image": (H, W, C), "features": (k,)}`` — the window
channel-last, as MiniGrid's ``image``, and the features after it; ``"image"`` the window
alone. As in MiniGrid, wrappers turn the dict into the other two:

* :class:`ImgObsWrapper` — only ``obs["image"]`` (MiniGrid's ``ImgObsWrapper``);
* :class:`FlatObsWrapper` — the image channel-first, row-major, then the features: exactly
  the default flat observation (MiniGrid's ``FlatObsWrapper`` flattens its dict likewise).

>>> from game.env import StealthEnv
>>> env = StealthEnv("maze", observation="dict")
>>> obs, _ = env.reset(seed=0)
>>> obs["image"].shape, obs["features"].shape
((5, 5, 3), (43,))
>>> flat, _ = FlatObsWrapper(env).reset(seed=0)
>>> bool((flat == StealthEnv("maze").reset(seed=0)[0]).all())
True
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from .observations import OBS_BOUND, PLAYER_CHANNELS, Observer

__all__ = ["OBSERVATIONS", "FlatObsWrapper", "ImgObsWrapper", "Layout", "player_layout"]

#: The observation kinds ``StealthEnv(observation=...)`` takes; the first is the default.
OBSERVATIONS = ("flat", "dict", "image")


class Layout:
    """Where the window and the features lie in a flat observation of ``channels`` channels
    of ``side`` × ``side`` cells followed by ``features`` numbers."""

    def __init__(self, channels: int, side: int, features: int) -> None:
        self.channels, self.side, self.features = channels, side, features
        self.window = channels * side * side

    def space(self, kind: str) -> spaces.Space:
        """The observation space of ``kind`` (one of :data:`OBSERVATIONS`)."""
        image = spaces.Box(0.0, OBS_BOUND, shape=(self.side, self.side, self.channels),
                           dtype=np.float32)
        features = spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(self.features,), dtype=np.float32)
        if kind == "image":
            return image
        if kind == "dict":
            return spaces.Dict({"image": image, "features": features})
        return spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(self.window + self.features,),
                          dtype=np.float32)

    def image(self, flat: np.ndarray) -> np.ndarray:
        """The window of ``flat`` as an (H, W, C) image (a copy, C-contiguous)."""
        chw = flat[:self.window].reshape(self.channels, self.side, self.side)
        return np.ascontiguousarray(chw.transpose(1, 2, 0))

    def convert(self, flat: np.ndarray, kind: str) -> Any:
        """``flat`` as an observation of ``kind``."""
        if kind == "image":
            return self.image(flat)
        if kind == "dict":
            return {"image": self.image(flat), "features": flat[self.window:].copy()}
        return flat


def player_layout(observer: Observer) -> Layout:
    """The layout of the player's observations made by ``observer``."""
    side = 2 * observer.radius + 1
    window = len(PLAYER_CHANNELS) * side * side
    return Layout(len(PLAYER_CHANNELS), side, observer.obs_size(False) - window)


def _dict_space(env: gymnasium.Env) -> spaces.Dict:
    space = env.observation_space
    if not isinstance(space, spaces.Dict) or {"image", "features"} - set(space.spaces):
        raise ValueError(f"the wrapper needs an env whose observations are dicts with "
                         f"'image' and 'features' (StealthEnv(observation='dict')), not {space}")
    return space


class ImgObsWrapper(gymnasium.ObservationWrapper):
    """Only the image of a dict observation (as MiniGrid's ``ImgObsWrapper``)."""

    def __init__(self, env: gymnasium.Env) -> None:
        super().__init__(env)
        self.observation_space = _dict_space(env)["image"]

    def observation(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        return observation["image"]


class FlatObsWrapper(gymnasium.ObservationWrapper):
    """A dict observation as one vector: the image channel-first and row-major, then the
    features — the layout of the default flat observation (docs/api.md)."""

    def __init__(self, env: gymnasium.Env) -> None:
        super().__init__(env)
        space = _dict_space(env)
        image, features = space["image"], space["features"]
        assert isinstance(image, spaces.Box) and isinstance(features, spaces.Box)
        size = int(np.prod(image.shape)) + int(np.prod(features.shape))
        self.observation_space = spaces.Box(-OBS_BOUND, OBS_BOUND, shape=(size,),
                                            dtype=np.float32)

    def observation(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        return np.concatenate([observation["image"].transpose(2, 0, 1).ravel(),
                               observation["features"]]).astype(np.float32, copy=False)
