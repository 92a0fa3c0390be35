"""One-call repairs in trimesh's style: a mesh in, the same kind of mesh out.

``trimesh.repair.fix_normals`` turns a mesh's faces outward only when the mesh is
watertight: on an open mesh it makes the winding consistent across shared edges and
leaves the direction to chance, and on an unwelded mesh (no shared edges) it changes
nothing.  :func:`fix_normals` and :func:`remove_hidden` answer by visibility instead
(:func:`meshvis.orient`, :func:`meshvis.remove_interior`), so holes, cracks and lost
connectivity do not matter.  Both take a ``trimesh.Trimesh`` or ``trimesh.Scene`` and
give the same kind back, with its visuals (UVs, texture, colours, materials) and, for a
scene, its graph and transforms; the input is not modified.  Their defaults are the
library's, the same as the command line's.
"""

from __future__ import annotations

from typing import Any


def fix_normals(mesh: Any, **options: Any) -> Any:
    """The mesh with every face turned so its front faces the outside.

    Parameters
    ----------
    mesh : trimesh.Trimesh or trimesh.Scene
        The mesh; open, unwelded or partly flipped is fine.  Not modified.
    **options
        Keywords of :func:`meshvis.orient` (``seed``, ``two_sided``, ``semantics``, ...)
        and of :func:`meshvis.classify` (``rays_per_node``, ...); unset ones take the
        library's defaults.

    Returns
    -------
    trimesh.Trimesh or trimesh.Scene
        The same kind as ``mesh``, with the same vertices and visuals; turned faces list
        their corners in the other order.

    Examples
    --------
    >>> import numpy as np, trimesh, meshvis
    >>> ball = trimesh.creation.icosphere(2)
    >>> open_ball = ball.submesh([ball.face_normals[:, 2] < 0.9], append=True)  # a hole on top
    >>> faces = open_ball.faces.copy(); faces[::4] = faces[::4, ::-1]  # every 4th face flipped
    >>> flipped = trimesh.Trimesh(open_ball.vertices, faces, process=False)
    >>> fixed = meshvis.fix_normals(flipped)
    >>> bool(np.allclose(fixed.face_normals, open_ball.face_normals))  # all outward again
    True
    """
    from meshvis.repair.orient import orient

    return orient(mesh, **options).soup.to_trimesh()


def remove_hidden(mesh: Any, **options: Any) -> Any:
    """The mesh without the faces that cannot be seen from outside.

    Parameters
    ----------
    mesh : trimesh.Trimesh or trimesh.Scene
        The mesh.  Not modified.
    **options
        Keywords of :func:`meshvis.remove_interior` (``visibility``, ``level``, ``region``,
        ``seed``, ...) and of :func:`meshvis.classify`; unset ones take the library's
        defaults.

    Returns
    -------
    trimesh.Trimesh or trimesh.Scene
        The same kind as ``mesh`` with the kept faces only, visuals kept.

    Examples
    --------
    >>> import numpy as np, trimesh, meshvis
    >>> outer, inner = trimesh.creation.box(), trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    >>> both = trimesh.util.concatenate([outer, inner])
    >>> len(meshvis.remove_hidden(both).faces)  # the inner box is gone
    12
    """
    from meshvis.repair.remove import remove_interior

    return remove_interior(mesh, **options).kept.to_trimesh()
