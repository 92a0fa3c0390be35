# SPDX-License-Identifier: GPL-3.0-or-later
"""meshvis in Blender: orient faces outward, remove hidden faces, peel layers, label parts.

A thin extension: the selected mesh objects become one triangle soup in world space, the
meshvis library (bundled as wheels) answers, and the answer is written back into the
meshes.  The sidebar panel is in the 3D view (N, tab *meshvis*).
"""

from __future__ import annotations

import bpy

from . import operators, panel

CLASSES = (*operators.CLASSES, *panel.CLASSES)


def register() -> None:
    """Register the operators, the panel and the scene settings."""
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.meshvis = bpy.props.PointerProperty(type=panel.MeshvisSettings)


def unregister() -> None:
    """Remove everything :func:`register` added."""
    del bpy.types.Scene.meshvis
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
