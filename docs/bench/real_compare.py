"""Two `meshvis bench real --json` runs side by side: object and both, per scene.

Usage (from the repository root):
    python docs/bench/real_compare.py A.json B.json

Prints one Markdown row per scene and method: removed area, reference-hidden area removed,
area no search saw removed, false pixels per million (mean and worst view), rays and time,
each as ``A → B``.
"""

import json
import sys

METHODS = ("object (graph cut)", "both")
COLUMNS = (
    ("removed_area", "removed", lambda x: f"{100 * x:.2f} %"),
    ("reference_hidden_removed", "ref.-hidden removed", lambda x: f"{100 * x:.1f} %"),
    ("unseen_removed", "unseen removed", lambda x: f"{100 * x:.1f} %"),
    ("false_pixels_mean", "false px mean", lambda x: f"{x:.1f}"),
    ("false_pixels_worst", "false px worst", lambda x: f"{x:.0f}"),
    ("rays", "rays", lambda x: f"{x / 1e6:.2f} M"),
    ("seconds", "time", lambda x: f"{x:.1f} s"),
)


def rows(path):
    """``{(model, method): row}`` of one JSON output."""
    data = json.load(open(path))
    return {(r["model"], row["method"]): row for r in data["results"] for row in r["rows"]}


a, b = rows(sys.argv[1]), rows(sys.argv[2])
print("| scene | method | " + " | ".join(title for _, title, _ in COLUMNS) + " |")
print("|---|---|" + "---:|" * len(COLUMNS))
for model, method in a:
    if method in METHODS and (model, method) in b:
        x, y = a[model, method], b[model, method]
        cells = [f"{fmt(x[key])} → {fmt(y[key])}" for key, _, fmt in COLUMNS]
        print(f"| {model} | {method.split(' ')[0]} | " + " | ".join(cells) + " |")
