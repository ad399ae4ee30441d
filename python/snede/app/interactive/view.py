"""A scene's fixed camera: a parallel projection, so a point of the window is a ray of one
direction, and the window's tools and the headless session map the pointer alike.

``View.ray(x, y)`` is the ray through window point (x, y) (0..1, y from the top);
``View.on_plane`` where it meets a plane (the tool's: the scalpel's edge lies on the beam's
front face); ``View.window`` the window point of a scene point (the inverse, for scripts).
The window sets VTK's camera from the same numbers (``camera`` gives them).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def direction_from_angles(elevation: float, azimuth: float) -> np.ndarray:
    """The direction of view (from the eye to the scene) of matplotlib's ``view_init(elevation,
    azimuth)`` (degrees), the scenes' ``VIEW``: the same camera for the window."""
    el, az = math.radians(elevation), math.radians(azimuth)
    return -np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


@dataclass(frozen=True)
class View:
    focal_point: tuple  # the scene point at the window's centre (metres)
    direction: tuple  # from the eye towards the scene
    up: tuple  # what is up in the window (made orthogonal to ``direction``)
    height: float  # the scene length the window's height spans (metres)
    aspect: float = 4 / 3  # the window's width / height

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(right, up, forward) unit vectors of the window in scene coordinates."""
        forward = np.asarray(self.direction, dtype=float)
        forward = forward / np.linalg.norm(forward)
        up = np.asarray(self.up, dtype=float)
        up = up - (up @ forward) * forward
        up = up / np.linalg.norm(up)
        return np.cross(forward, up), up, forward

    def ray(self, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
        """(a point, the direction) of the ray through window point (x, y)."""
        right, up, forward = self.axes()
        across = (x - 0.5) * self.height * self.aspect * right + (0.5 - y) * self.height * up
        return np.asarray(self.focal_point, dtype=float) + across, forward

    def on_plane(self, x: float, y: float, point, normal) -> np.ndarray:
        """Where the ray through (x, y) meets the plane through ``point`` with ``normal``."""
        origin, forward = self.ray(x, y)
        normal = np.asarray(normal, dtype=float)
        facing = forward @ normal
        if abs(facing) < 1e-9:
            raise ValueError("the tool's plane is seen edge-on: this view cannot place the tool on it")
        return origin + ((np.asarray(point, dtype=float) - origin) @ normal / facing) * forward

    def window(self, point) -> tuple[float, float]:
        """The window point (x, y) where a scene point is seen."""
        right, up, _ = self.axes()
        offset = np.asarray(point, dtype=float) - np.asarray(self.focal_point, dtype=float)
        return 0.5 + offset @ right / (self.height * self.aspect), 0.5 - offset @ up / self.height

    def camera(self, distance: float = 1.0) -> dict:
        """VTK's camera for this view (pyvista's ``Camera``): position, focal point, view up,
        parallel scale (half the window's height), parallel projection."""
        _, up, forward = self.axes()
        focal = np.asarray(self.focal_point, dtype=float)
        return {"position": tuple(focal - distance * forward), "focal_point": tuple(focal), "up": tuple(up),
                "parallel_scale": self.height / 2}
