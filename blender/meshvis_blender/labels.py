# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender's camera as a meshvis camera, and a label layout as text objects with leader curves.

The layout is in image pixels.  Each label becomes a text object on a plane facing the
camera, just in front of the model, and a leader curve from the surface point under the
anchor to the box: seen through the camera, both land on the pixels the layout chose.
"""

from __future__ import annotations

import math

import bpy
import numpy as np

#: name of the collection that holds the labels (emptied and refilled on every update)
COLLECTION = "meshvis labels"
#: the label plane's distance, as a share of the nearest model point's depth
PLANE_DEPTH = 0.9
#: leader curve thickness in pixels
LEADER_PIXELS = 0.6


def image_size(scene, longest: int) -> tuple[int, int]:
    """The render's width and height, scaled so that the longer side is ``longest`` pixels."""
    r = scene.render
    w = r.resolution_x * r.pixel_aspect_x
    h = r.resolution_y * r.pixel_aspect_y
    k = longest / max(w, h)
    return max(1, round(w * k)), max(1, round(h * k))


def camera(cam_ob, size: tuple[int, int]):
    """A :class:`meshvis.Camera` seeing what the Blender camera ``cam_ob`` sees at ``size``."""
    from meshvis.rays.camera import Camera

    m = np.array(cam_ob.matrix_world, np.float64)
    position = m[:3, 3]
    forward = -m[:3, 2] / np.linalg.norm(m[:3, 2])
    up = m[:3, 1]
    data = cam_ob.data
    w, h = size
    fit = data.sensor_fit
    horizontal = fit == "HORIZONTAL" or (fit == "AUTO" and w >= h)
    if data.type == "ORTHO":
        height = data.ortho_scale * (h / w if horizontal else 1.0)
        return Camera(position, position + forward, up=up, orthographic=True, ortho_height=height)
    sensor = data.sensor_height if fit == "VERTICAL" else data.sensor_width
    half = math.atan(0.5 * sensor / data.lens)
    if horizontal:
        half = math.atan(math.tan(half) * h / w)
    return Camera(position, position + forward, up=up, fov=math.degrees(2 * half))


def plane_depth(cam, points: np.ndarray, clip_start: float) -> float:
    """Depth of the label plane: a little in front of the nearest of ``points``."""
    depth = (np.asarray(points) - cam.position) @ cam.basis()[2]
    ahead = depth[depth > clip_start]
    return max(PLANE_DEPTH * float(ahead.min()) if len(ahead) else 1.0, 2 * clip_start)


class _Plane:
    """Pixels to world points on the plane ``depth`` in front of a camera."""

    def __init__(self, cam, size: tuple[int, int], depth: float):
        self.cam, self.depth = cam, depth
        self.w, self.h = size
        self.right, self.up, self.forward = cam.basis()
        hh = cam._half_height()
        self.hh = hh * (1.0 if cam.orthographic else depth)
        self.hw = self.hh * self.w / self.h

    @property
    def pixel(self) -> float:
        """World length of one pixel on the plane."""
        return 2 * self.hh / self.h

    def point(self, xy) -> np.ndarray:
        x, y = float(xy[0]), float(xy[1])
        gx = (x / self.w * 2 - 1) * self.hw
        gy = (1 - y / self.h * 2) * self.hh
        return self.cam.position + self.depth * self.forward + gx * self.right + gy * self.up

    def rotation(self) -> np.ndarray:
        return np.column_stack([self.right, self.up, -self.forward])


def _collection(scene):
    coll = bpy.data.collections.get(COLLECTION)
    if coll is None:
        coll = bpy.data.collections.new(COLLECTION)
    if coll.name not in scene.collection.children:
        scene.collection.children.link(coll)
    for ob in list(coll.objects):
        data = ob.data
        bpy.data.objects.remove(ob)
        if data is not None and data.users == 0:
            bpy.data.curves.remove(data)
    return coll


def place(scene, result, depth: float) -> list:
    """Text objects and leader curves of a :class:`meshvis.labeling.LayoutResult`.

    Earlier labels in the :data:`COLLECTION` are removed first.  Returns the new objects.
    """
    coll = _collection(scene)
    plane = _Plane(result.camera, result.size, depth)
    rotation = plane.rotation()
    made = []
    style_pad = 3.0
    for label in result.labels:  # a few dozen labels at most
        text = bpy.data.curves.new(f"label {label.text}", "FONT")
        text.body = label.text
        text.size = result.font_size * plane.pixel
        west = label.side == "west"
        text.align_x = "RIGHT" if west else "LEFT"
        text.align_y = "CENTER"
        x0, y0, x1, y1 = (float(v) for v in label.box)
        at = plane.point((x1 - style_pad if west else x0 + style_pad, 0.5 * (y0 + y1)))
        ob = bpy.data.objects.new(text.name, text)
        ob.matrix_world = _matrix(rotation, at)
        coll.objects.link(ob)
        leader = bpy.data.curves.new(f"leader {label.text}", "CURVE")
        leader.dimensions = "3D"
        leader.bevel_depth = LEADER_PIXELS * plane.pixel
        points = [np.asarray(label.anchor_3d, np.float64)] + [plane.point(p) for p in label.leader[1:]]
        spline = leader.splines.new("POLY")
        spline.points.add(len(points) - 1)
        spline.points.foreach_set("co", np.hstack([points, np.ones((len(points), 1))]).ravel())
        line = bpy.data.objects.new(leader.name, leader)
        coll.objects.link(line)
        ob["meshvis_part"] = line["meshvis_part"] = label.name
        made += [ob, line]
    return made


def _matrix(rotation: np.ndarray, at: np.ndarray):
    from mathutils import Matrix

    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = at
    return Matrix(m.tolist())
