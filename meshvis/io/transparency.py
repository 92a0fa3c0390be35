"""Which materials let sight through: the rules the readers apply to set :attr:`Material.see_through`.

A viewer sees what lies behind a windshield, a glass pane or the cut-out parts of a leaf
texture, so removal by sight must not delete it.  A material counts as see-through when
its file says that light passes it:

* glTF: ``alphaMode`` ``"BLEND"`` (blended with what lies behind); ``"MASK"`` whose base
  colour alpha is below ``alphaCutoff`` (the whole material is cut away); the extension
  ``KHR_materials_transmission`` with a ``transmissionFactor`` above 0;
* MTL: dissolve ``d`` below 1, or transparency ``Tr`` above 0 (``Tr = 1 - d``).

A texture's alpha channel is not read: a MASK material with an opaque base colour counts as
a wall (its cut-outs depend on texels, which the ray tracer does not sample).

>>> gltf_see_through({"alphaMode": "BLEND"}), gltf_see_through({"alphaMode": "OPAQUE"})
(True, False)
>>> mtl_see_through("d 0.3"), mtl_see_through("Tr 0")
(True, False)
"""

from __future__ import annotations

from typing import Any

#: glTF's default ``alphaCutoff`` of a MASK material
GLTF_ALPHA_CUTOFF = 0.5


def gltf_see_through(material: Any) -> bool:
    """Whether a glTF material (its JSON object) lets sight through (module notes).

    Parameters
    ----------
    material : dict
        One entry of the document's ``materials``; anything else counts as opaque.

    Returns
    -------
    bool

    Examples
    --------
    >>> gltf_see_through({"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.2]}})
    True
    >>> gltf_see_through({"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}})
    True
    """
    if not isinstance(material, dict):
        return False
    mode = material.get("alphaMode")
    if mode == "BLEND":
        return True
    if mode == "MASK":
        pbr = material.get("pbrMetallicRoughness")
        factor = pbr.get("baseColorFactor") if isinstance(pbr, dict) else None
        alpha = _number(factor[3], 1.0) if isinstance(factor, list) and len(factor) == 4 else 1.0
        if alpha < _number(material.get("alphaCutoff"), GLTF_ALPHA_CUTOFF):
            return True
    ext = material.get("extensions")
    transmission = ext.get("KHR_materials_transmission") if isinstance(ext, dict) else None
    if isinstance(transmission, dict):
        return _number(transmission.get("transmissionFactor"), 0.0) > 0
    return False


def mtl_see_through(text: str) -> bool:
    """Whether an MTL material block (its statements) lets sight through: ``d`` < 1 or ``Tr`` > 0.

    Parameters
    ----------
    text : str
        The statements of one ``newmtl`` block.

    Returns
    -------
    bool
        The last ``d`` or ``Tr`` statement decides; an unreadable value counts as opaque.

    Examples
    --------
    >>> mtl_see_through("d -halo 0.5"), mtl_see_through(chr(10).join(["Tr 0.25", "d 1"]))
    (True, False)
    """
    see_through = False
    for line in text.splitlines():
        parts = line.split()
        if len(parts) < 2 or parts[0].lower() not in ("d", "tr"):
            continue
        value = _number(parts[-1], None)
        if value is not None:
            see_through = value < 1.0 if parts[0].lower() == "d" else value > 0.0
    return see_through


def _number(value: Any, default: Any) -> Any:
    """``value`` as a float, or ``default`` when it is not a finite number."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        return default
    return x if x == x and abs(x) != float("inf") else default
