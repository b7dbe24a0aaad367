"""Level geometry, triangulation, node graphs and pathfinding (imports nothing of ai/game/headless)."""
