# SPDX-License-Identifier: GPL-3.0-or-later
"""The sidebar panel (3D view > N > meshvis) and the scene settings it edits."""

from __future__ import annotations

import bpy

from . import operators as ops


def _is_empty(self, ob) -> bool:
    return ob.type == "EMPTY"


class MeshvisSettings(bpy.types.PropertyGroup):
    """The panel's choices, kept with the scene and handed to the operators."""

    region: bpy.props.EnumProperty(name="Viewers", items=ops.REGIONS, default="OUTSIDE")
    box: bpy.props.PointerProperty(name="Box", type=bpy.types.Object, poll=_is_empty)
    action: bpy.props.EnumProperty(name="Action", items=ops.ACTIONS, default="DELETE")
    level: bpy.props.EnumProperty(
        name="Level", items=ops._LEVELS, default=ops.identifier(ops._REMOVAL["level"])
    )
    visibility: bpy.props.EnumProperty(
        name="Judged by", items=ops._MODES, default=ops.identifier(ops._REMOVAL["visibility"])
    )
    see_through: bpy.props.BoolProperty(
        name="Transparent materials see-through", default=ops._REMOVAL["transparent"] == "see-through"
    )
    max_layers: bpy.props.IntProperty(name="Max layers", default=0, min=0)
    layout: bpy.props.EnumProperty(
        name="Layout", items=ops._LAYOUTS, default=ops.identifier(ops._LABELING["layout"])
    )


class MESHVIS_PT_panel(bpy.types.Panel):
    """meshvis in the 3D view's sidebar."""

    bl_label = "meshvis"
    bl_idname = "MESHVIS_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "meshvis"

    def draw(self, context):
        """Draw the settings and the four buttons."""
        draw(self.layout, context.scene.meshvis)


def draw(layout, s) -> None:
    """The panel's layout for the settings ``s`` (also used to draw it outside Blender's UI)."""
    box = layout.box()
    box.label(text="Viewers", icon="HIDE_OFF")
    box.prop(s, "region", text="")
    if s.region == "BOX":
        box.prop(s, "box", text="")
    col = layout.column(align=True)
    op = col.operator(ops.MESHVIS_OT_orient.bl_idname, icon="NORMALS_FACE")
    op.region = s.region
    op.box = s.box.name if s.box else ""

    col = layout.column(align=True)
    col.prop(s, "action")
    col.prop(s, "level")
    col.prop(s, "visibility")
    col.prop(s, "see_through")
    op = col.operator(ops.MESHVIS_OT_remove_hidden.bl_idname, icon="HIDE_ON")
    for key in ("action", "level", "visibility", "see_through", "region"):
        setattr(op, key, getattr(s, key))
    op.box = s.box.name if s.box else ""

    col = layout.column(align=True)
    col.prop(s, "max_layers")
    op = col.operator(ops.MESHVIS_OT_layers.bl_idname, icon="OUTLINER_COLLECTION")
    op.max_layers = s.max_layers

    col = layout.column(align=True)
    col.prop(s, "layout")
    op = col.operator(ops.MESHVIS_OT_label_parts.bl_idname, icon="FONT_DATA")
    op.layout = s.layout


CLASSES = (MeshvisSettings, MESHVIS_PT_panel)
