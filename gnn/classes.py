"""The detector's classes: the five RadarScenes object classes plus background.

Index order follows RadarScenes' ``ClassificationLabel`` and RadarGNN
(0 car, 1 pedestrian, 2 pedestrian group, 3 two-wheeler, 4 large vehicle, 5 background =
RadarScenes "static": everything that is not a moving road user).
"""

from __future__ import annotations

from model.scene import OBJECT_LABELS

CLASSES: tuple[str, ...] = (*OBJECT_LABELS, "background")
"""Class names by index (the scene's object labels, ``model.scene.OBJECT_LABELS``, then
background)."""
OBJECT_CLASSES: tuple[str, ...] = OBJECT_LABELS
"""The five object classes (everything except background)."""
NUM_CLASSES = len(CLASSES)
BACKGROUND = CLASSES.index("background")
"""Index of the background class."""


def class_index(name: str) -> int:
    """Index of class ``name``; ValueError naming the valid classes otherwise."""
    try:
        return CLASSES.index(name)
    except ValueError:
        raise ValueError(f"class: unknown class {name!r}; choose one of "
                         f"{', '.join(CLASSES)}") from None
