"""The game on a large level: its size policy and the work done beside the frames."""
