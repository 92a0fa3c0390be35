# SPDX-License-Identifier: GPL-3.0-or-later
"""The four operators: Orient Outside, Remove Hidden, Layers and Label Parts.

Each one snapshots the selected objects as arrays (:mod:`.convert`), runs the library in a
background thread (:mod:`.jobs`) while Blender's progress bar follows it, and writes the
result back in one step when it is done; Esc cancels.  Run from the 3D view they are modal
(a timer polls the worker; view navigation passes through, other input waits); run from a
script, or again from the *Adjust Last Operation* panel, ``execute`` does the same work in
the foreground.  Nothing is written before the last step, so the undo step Blender pushes
when the operator finishes holds the whole change, and a cancelled run leaves nothing to
undo.
"""

from __future__ import annotations

import contextlib
import time

import bpy
import numpy as np

from . import convert, defaults, labels
from .jobs import Cancelled, Job

#: seconds between two looks at the worker
POLL_SECONDS = 0.1
#: events that move the view while the worker runs; everything else waits
NAVIGATION = {
    "MIDDLEMOUSE",
    "WHEELUPMOUSE",
    "WHEELDOWNMOUSE",
    "MOUSEMOVE",
    "INBETWEEN_MOUSEMOVE",
    "TRACKPADPAN",
    "TRACKPADZOOM",
    "MOUSEROTATE",
    "NDOF_MOTION",
}
REGIONS = [
    ("OUTSIDE", "Outside", "Viewers anywhere outside the model (the graph cut and lines of sight)"),
    ("CAMERA", "Active camera", "A viewer at the active camera's position"),
    ("BOX", "Box empty", "Viewers anywhere in the box of the named empty"),
    ("UPPER", "Upper hemisphere", "Viewers above the model (z up)"),
]


def identifier(name: str) -> str:
    """The Blender enum identifier of a library choice (``left-right`` -> ``LEFT_RIGHT``)."""
    return name.upper().replace("-", "_")


def choice(identifier_: str) -> str:
    """The library choice of a Blender enum identifier."""
    return identifier_.lower().replace("_", "-")


def _enum(names, labels_: dict | None = None):
    labels_ = labels_ or {}
    return [(identifier(n), labels_.get(n, n.replace("-", " ").title()), "") for n in names]


def _selected_meshes(context) -> list:
    return [ob for ob in context.selected_objects if ob.type == "MESH" and len(ob.data.polygons)]


def region_text(context, region: str, box: str) -> str:
    """The library's region (:func:`meshvis.parse_region`) for a choice of :data:`REGIONS`."""
    if region == "OUTSIDE":
        return "outside"
    if region == "UPPER":
        return "upper-hemisphere:0,0,1"
    if region == "CAMERA":
        cam = context.scene.camera
        if cam is None:
            raise ValueError("the scene has no active camera")
        return "points:" + ",".join(repr(float(v)) for v in cam.matrix_world.translation)
    empty = bpy.data.objects.get(box)
    if empty is None or empty.type != "EMPTY":
        raise ValueError(f"no empty named {box!r} for the box region")
    size = empty.empty_display_size
    corners = np.array([[x, y, z, 1.0] for x in (-size, size) for y in (-size, size) for z in (-size, size)])
    world = corners @ np.array(empty.matrix_world).T
    lo, hi = world[:, :3].min(axis=0), world[:, :3].max(axis=0)
    return "box:" + ",".join(repr(float(v)) for v in (*lo, *hi))


class _Background:
    """What the four operators share: snapshot, worker, progress, cancel, apply."""

    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        """Selected meshes, in object mode."""
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode")
            return False
        if not _selected_meshes(context):
            cls.poll_message_set("Select one or more mesh objects")
            return False
        return True

    # what each operator defines
    def prepare(self, context):
        """Snapshot the input in the main thread; return ``work(progress) -> result``."""
        raise NotImplementedError

    def apply(self, context, result) -> str:
        """Write ``result`` into Blender (main thread); return the line to report."""
        raise NotImplementedError

    # shared
    def _start(self, context):
        self._scene = None
        try:
            work = self.prepare(context)
        except ValueError as exc:
            self.report({"ERROR"}, str(exc))
            return None
        self._t0 = time.perf_counter()
        return Job(work)

    def _finish(self, context, job: Job):
        if job.error is not None:
            if isinstance(job.error, Cancelled):
                self.report({"WARNING"}, "meshvis: cancelled, nothing changed")
            else:
                self.report({"ERROR"}, f"meshvis: {job.error}")
                print(job.details)
            return {"CANCELLED"}
        if not self._unchanged():
            self.report({"ERROR"}, "meshvis: the meshes changed while meshvis worked; nothing written")
            return {"CANCELLED"}
        line = self.apply(context, job.result)
        self.report({"INFO"}, f"meshvis: {line}; {time.perf_counter() - self._t0:.1f} s")
        return {"FINISHED"}

    def _unchanged(self) -> bool:
        """Whether every snapshotted object still has the polygons it had."""
        s = self._scene
        if s is None:
            return True
        try:
            return all(len(ob.data.polygons) == n for ob, n in zip(s.objects, s.polygon_counts))
        except ReferenceError:  # an object was deleted meanwhile
            return False

    def execute(self, context):
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        with contextlib.suppress(BaseException):  # recorded on the job, reported by _finish
            job.run()
        return self._finish(context, job)

    def invoke(self, context, event):
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        self._job = job.start()
        wm = context.window_manager
        self._timer = wm.event_timer_add(POLL_SECONDS, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        context.workspace.status_text_set("meshvis: working (Esc cancels)")
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC":
            job.cancel()  # the worker stops at the library's next progress report
            self._end(context)
            self.report({"WARNING"}, "meshvis: cancelled, nothing changed")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"} if event.type in NAVIGATION else {"RUNNING_MODAL"}
        context.window_manager.progress_update(100 * job.fraction)
        if not job.done:
            return {"RUNNING_MODAL"}
        self._end(context)
        return self._finish(context, job)

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def snapshot(self, context):
        """The selected meshes as one soup in world space (kept to check them at the end)."""
        self._scene = convert.read_scene(_selected_meshes(context))
        return self._scene


def _per_mesh(scene, values: list[np.ndarray]):
    """Objects grouped by the mesh they share, with each one's polygon values.

    Yields ``(object, values)`` once per mesh where every user wants the same, and gives an
    object of its own copy of the mesh where its users disagree.
    """
    seen: dict = {}
    for ob, v in zip(scene.objects, values):
        first = seen.get(ob.data.name)
        if first is None:
            seen[ob.data.name] = v
            yield ob, v
        elif not np.array_equal(first, v):
            ob.data = ob.data.copy()
            yield ob, v


class MESHVIS_OT_orient(_Background, bpy.types.Operator):
    """Turn every face of the selected objects toward the outside, judged by what can be seen."""

    bl_description = "Turn every face of the selected objects toward the outside, judged by what can be seen"

    bl_idname = "meshvis.orient"
    bl_label = "Orient Outside (visibility)"

    region: bpy.props.EnumProperty(name="Viewers", items=REGIONS, default="OUTSIDE")
    box: bpy.props.StringProperty(name="Box empty", description="Empty whose box holds the viewers")
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0)

    def prepare(self, context):
        """Snapshot the selection; the work orients it toward the viewers."""
        region = region_text(context, self.region, self.box)
        soup = self.snapshot(context).soup()
        seed = self.seed

        def work(progress):
            import meshvis

            if region == "outside":
                return meshvis.orient(soup, seed=seed, progress=progress).flipped
            return meshvis.orient_from(soup, region, seed=seed).flipped

        return work

    def apply(self, context, flipped) -> str:
        """Turn the polygons whose triangles, by area, were turned."""
        per_object = self._scene.per_polygon(flipped, "area")
        turned = sum(convert.flip_polygons(ob.data, v) for ob, v in _per_mesh(self._scene, per_object))
        total = int(self._scene.polygon_counts.sum())
        return f"turned {turned} of {total} faces"


ACTIONS = [
    ("DELETE", "Delete", "Delete the faces nobody sees"),
    ("SELECT", "Select", "Select the faces nobody sees (and nothing else)"),
    ("SEPARATE", "Move to New Object", "Move the faces nobody sees into new objects"),
]


def _removal_items():
    d = defaults.removal()
    levels = _enum(d["levels"], {"part": "Object"})
    modes = _enum(d["visibility_modes"], {"object": "Graph cut", "view": "Lines of sight", "both": "Both"})
    return d, levels, modes


_REMOVAL, _LEVELS, _MODES = _removal_items()


class MESHVIS_OT_remove_hidden(_Background, bpy.types.Operator):
    """Delete, select or separate the faces of the selected objects that nobody can see."""

    bl_description = "Delete, select or separate the faces of the selected objects that nobody can see"

    bl_idname = "meshvis.remove_hidden"
    bl_label = "Remove Hidden"

    action: bpy.props.EnumProperty(name="Action", items=ACTIONS, default="DELETE")
    level: bpy.props.EnumProperty(name="Level", items=_LEVELS, default=identifier(_REMOVAL["level"]))
    visibility: bpy.props.EnumProperty(
        name="Judged by", items=_MODES, default=identifier(_REMOVAL["visibility"])
    )
    region: bpy.props.EnumProperty(name="Viewers", items=REGIONS, default="OUTSIDE")
    box: bpy.props.StringProperty(name="Box empty")
    see_through: bpy.props.BoolProperty(
        name="Transparent materials see-through",
        description="Faces with a transparent material do not hide what is behind them",
        default=_REMOVAL["transparent"] == "see-through",
    )
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0)

    def prepare(self, context):
        """Snapshot the selection; the work finds the faces nobody sees."""
        region = region_text(context, self.region, self.box)
        scene = self.snapshot(context)
        soup = scene.soup()
        options = dict(
            visibility=choice(self.visibility),
            region=region,
            level=choice(self.level),
            transparent="see-through" if self.see_through else "opaque",
        )
        seed = self.seed

        def work(progress):
            import meshvis

            r = meshvis.remove_interior(soup, seed=seed, progress=progress, **options)
            report = r.report(per_face=False)
            line = (
                f"{report['removed_faces']} of {report['input_faces']} triangles hidden "
                f"({100 * report['removed_area_fraction']:.1f} % of the area)"
            )
            # the removal's own console lines after the first (the search's budget, the self-check)
            return r.keep, "; ".join([line, *r.summary()[1:]])

        return work

    def apply(self, context, result) -> str:
        """Delete, select or separate the polygons all of whose triangles are hidden."""
        keep, line = result
        hidden = self._scene.per_polygon(~keep, "all")
        pairs = list(_per_mesh(self._scene, hidden))
        n = int(sum(v.sum() for _, v in pairs))
        if self.action == "SELECT":
            for ob, v in pairs:
                convert.select_polygons(ob.data, v)
            return f"{line}; selected {n} faces"
        made = convert.delete_polygons(context, pairs, separate=self.action == "SEPARATE")
        for ob in made:
            ob.name = f"{ob.name.rsplit('.', 1)[0]} hidden"
        verb = "moved" if self.action == "SEPARATE" else "deleted"
        return f"{line}; {verb} {n} faces"


class MESHVIS_OT_layers(_Background, bpy.types.Operator):
    """Peel the selected objects into layers: one collection per layer, the outer one first."""

    bl_description = "Peel the selected objects into layers: one collection per layer, the outer one first"

    bl_idname = "meshvis.layers"
    bl_label = "Layers"

    max_layers: bpy.props.IntProperty(name="Max layers", description="0: all of them", default=0, min=0)
    seed: bpy.props.IntProperty(name="Seed", default=0, min=0)

    def prepare(self, context):
        """Snapshot the selection; the work peels its layers."""
        soup = self.snapshot(context).soup()
        max_layers = self.max_layers or None
        seed = self.seed

        def work(progress):
            import meshvis

            def peeled(layer: int, done: int, total: int) -> None:
                progress("layers", done / max(total, 1))

            return meshvis.layers(soup, max_layers=max_layers, seed=seed, progress=peeled).layer

        return work

    def apply(self, context, layer) -> str:
        """Copy each object once per layer it has faces in, keeping that layer's polygons."""
        per_object = self._scene.per_polygon(layer, "min")
        n = int(max(v.max() for v in per_object))
        parent = bpy.data.collections.new("meshvis layers")
        context.scene.collection.children.link(parent)
        copies = []
        for k in range(1, n + 1):
            coll = bpy.data.collections.new(f"Layer {k}")
            parent.children.link(coll)
            for ob, v in zip(self._scene.objects, per_object):
                if not (v == k).any():
                    continue
                copy = ob.copy()
                copy.data = ob.data.copy()
                copy.name = f"{ob.name} layer {k}"
                coll.objects.link(copy)
                copies.append((copy, v != k))
        convert.delete_polygons(context, copies)
        for ob in self._scene.objects:
            ob.hide_set(True)
        counts = ", ".join(str(int(sum((v == k).sum() for v in per_object))) for k in range(1, n + 1))
        return f"{n} layers ({counts} faces); the originals are hidden"


def _layouts():
    d = defaults.labeling()
    return d, _enum(d["layouts"])


_LABELING, _LAYOUTS = _layouts()


class MESHVIS_OT_label_parts(_Background, bpy.types.Operator):
    """Label the selected objects for the active camera: text objects with leader curves."""

    bl_description = "Label the selected objects for the active camera: text objects with leader curves"

    bl_idname = "meshvis.label_parts"
    bl_label = "Label Parts"

    layout: bpy.props.EnumProperty(name="Layout", items=_LAYOUTS, default=identifier(_LABELING["layout"]))
    resolution: bpy.props.IntProperty(
        name="Pixels", description="Longer side of the image the layout is made in", default=768, min=128
    )

    @classmethod
    def poll(cls, context):
        """An active camera and selected meshes, in object mode."""
        if context.scene.camera is None:
            cls.poll_message_set("The scene needs an active camera")
            return False
        return super().poll(context)

    def prepare(self, context):
        """Snapshot the selection and the camera; the work lays the labels out."""
        scene = self.snapshot(context)
        soup = scene.soup()
        size = labels.image_size(context.scene, self.resolution)
        cam = labels.camera(context.scene.camera, size)
        self._depth = labels.plane_depth(cam, scene.vertices, context.scene.camera.data.clip_start)
        layout = choice(self.layout)

        def work(progress):
            from meshvis.labeling import layout as place

            progress("sampling", 0.0)
            return place(soup, cam, layout=layout, size=size)

        return work

    def apply(self, context, result) -> str:
        """Replace the label objects with this layout's."""
        labels.place(context.scene, result, self._depth)
        missing = len(result.unplaced) + len(result.invisible)
        more = f", {missing} parts not labelled" if missing else ""
        return f"{len(result.labels)} labels in '{labels.COLLECTION}'{more}"


CLASSES = (MESHVIS_OT_orient, MESHVIS_OT_remove_hidden, MESHVIS_OT_layers, MESHVIS_OT_label_parts)
