"""The page of ``meshvis view`` inside Jupyter: an anywidget that frames it.

:func:`view` starts the same local server as ``meshvis view`` in a background thread of
the kernel (127.0.0.1, a free port) and returns a widget that shows its page in an
iframe, so the notebook gets the model with orbit controls and labels that follow it.
Needs the ``notebook`` extra (``pip install meshvis[notebook]``, i.e. anywidget).

>>> import meshvis.labeling.widget as w  # doctest: +SKIP
>>> w.view("models/assembly.obj", layout="silhouette")  # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from meshvis._extras import import_extra

from .live import LiveLabeler
from .server import ViewServer

#: the widget's front end: an iframe on the server's page
_ESM = """
function render({ model, el }) {
  const frame = document.createElement("iframe");
  const size = () => {
    frame.src = model.get("url");
    frame.style.width = model.get("width") + "px";
    frame.style.height = model.get("height") + "px";
    frame.style.border = "0";
  };
  size();
  model.on("change:url", size);
  model.on("change:width", size);
  model.on("change:height", size);
  el.appendChild(frame);
}
export default { render };
"""


def _widget_class() -> type:
    """The widget class (anywidget is imported only when a widget is made)."""
    anywidget = import_extra("anywidget", "the notebook view")
    import traitlets

    class LabelView(anywidget.AnyWidget):
        """The labeled model in a notebook cell (see :func:`view`)."""

        _esm = _ESM
        url = traitlets.Unicode("").tag(sync=True)
        width = traitlets.Int(800).tag(sync=True)
        height = traitlets.Int(500).tag(sync=True)

    return LabelView


def view(
    model: Any,
    *,
    layout: str = "left-right",
    texts: Mapping[Any, str] | None = None,
    width: int = 800,
    height: int = 500,
    port: int = 0,
    **options: Any,
) -> Any:
    """Show a model with live labels in a notebook.

    Parameters
    ----------
    model : a path, Soup or trimesh object (see :class:`meshvis.labeling.live.LiveLabeler`)
    layout : the label layout
    texts : label texts {part name or index: text}
    width, height : size of the frame in the notebook, CSS pixels
    port : port of the server on 127.0.0.1 (0: any free one)
    **options : passed to :class:`~meshvis.labeling.live.LiveLabeler` (``up``, ``min_pixels``, ...)

    Returns
    -------
    LabelView
        An anywidget; ``widget.server`` is the :class:`~meshvis.labeling.server.ViewServer`
        behind it (``widget.server.shutdown()`` stops it).

    Raises
    ------
    MissingExtraError
        anywidget is not installed.
    """
    cls = _widget_class()
    path = str(model) if isinstance(model, (str, bytes)) or hasattr(model, "__fspath__") else None
    live = LiveLabeler(model, layout=layout, texts=texts, **options)
    server = ViewServer(live, path, port=port).start()
    widget = cls(url=server.url, width=int(width), height=int(height))
    widget.server = server
    return widget
