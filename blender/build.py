"""Build the Blender extension: ``python blender/build.py`` -> ``dist/meshvis_blender-<version>.zip``.

The zip is what Blender's *Install from Disk* (or a drag and drop onto its window) takes:
the add-on's Python package, its ``blender_manifest.toml`` and, in ``wheels/``, the wheels
of meshvis and of the libraries its operators import, for one platform.  NumPy is left out:
Blender ships it, and its copy is the one the add-on runs with, so the other wheels are
resolved against the NumPy of the Blender targeted (``--numpy``).  Matplotlib comes only for
the label font, Pillow for measuring label texts; nothing the operators do not import is
bundled (no PyMaxflow, libigl, rich or lxml).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PACKAGE = HERE / "meshvis_blender"
#: what the operators import, besides meshvis itself and NumPy
REQUIREMENTS = ["scipy", "trimesh", "embreex", "numba", "platformdirs", "pillow", "matplotlib"]
#: Blender's Python
PYTHON = "3.11"
#: pip's platform tag of each Blender platform name
PLATFORMS = {
    "linux-x64": "manylinux_2_28_x86_64",
    "windows-x64": "win_amd64",
    "macos-arm64": "macosx_11_0_arm64",
    "macos-x64": "macosx_10_15_x86_64",
}
#: the NumPy of Blender 4.2-5.0's Python (the wheels are resolved against it)
DEFAULT_NUMPY = "1.26.4"


def version() -> str:
    """The version of meshvis, read from its one place."""
    text = (ROOT / "meshvis" / "_version.py").read_text()
    return re.search(r'__version__ = "([^"]+)"', text).group(1)


def host_platform() -> str:
    """The Blender platform name of this machine."""
    import platform

    machine = platform.machine().lower()
    arm = machine in ("arm64", "aarch64")
    if sys.platform.startswith("linux") and not arm:
        return "linux-x64"
    if sys.platform == "darwin":
        return "macos-arm64" if arm else "macos-x64"
    if sys.platform == "win32" and not arm:
        return "windows-x64"
    raise SystemExit(f"no wheels for {sys.platform} {machine}: name a platform with --platform")


def _pip(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "pip", *args, "--disable-pip-version-check", "-q"], check=True)


def collect_wheels(folder: Path, platform: str, numpy: str) -> list[Path]:
    """The wheel of meshvis, built from this checkout, and those of its runtime libraries for ``platform``."""
    folder.mkdir(parents=True, exist_ok=True)
    _pip("wheel", str(ROOT), "--no-deps", "-w", str(folder))
    target = ["--only-binary=:all:", "--python-version", PYTHON, "--implementation", "cp"]
    target += ["--platform", PLATFORMS[platform]]
    if platform == "linux-x64":  # manylinux wheels older than 2_28 are fine too
        target += ["--platform", "manylinux2014_x86_64", "--platform", "manylinux_2_17_x86_64"]
    _pip("download", *target, "-d", str(folder), f"numpy=={numpy}", *REQUIREMENTS)
    for numpy_wheel in folder.glob("numpy-*.whl"):
        numpy_wheel.unlink()  # Blender's own is used
    return sorted(folder.glob("*.whl"))


def manifest(wheels: list[Path], platform: str) -> str:
    """The repository's manifest with this build's version, platform and wheels."""
    text = (PACKAGE / "blender_manifest.toml").read_text()
    text = re.sub(r'(?m)^version = ".*"$', f'version = "{version()}"', text)
    listed = ",\n".join(f'  "./wheels/{w.name}"' for w in wheels)
    top, table, tables = text.partition("\n[")  # top-level keys go before the first table
    return f'{top}\nplatforms = ["{platform}"]\nwheels = [\n{listed},\n]\n{table}{tables}'


def build(out: Path, platform: str, numpy: str) -> Path:
    """Write the extension zip into ``out`` and return its path."""
    with tempfile.TemporaryDirectory() as tmp:
        wheels = collect_wheels(Path(tmp) / "wheels", platform, numpy)
        out.mkdir(parents=True, exist_ok=True)
        path = out / f"meshvis_blender-{version()}.zip"
        partial = path.with_suffix(".zip.tmp")
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
            for source in sorted(PACKAGE.glob("*.py")):
                z.write(source, source.name)
            z.write(ROOT / "LICENSE", "LICENSE")
            z.writestr("blender_manifest.toml", manifest(wheels, platform))
            for wheel in wheels:  # wheels are compressed already
                z.write(wheel, f"wheels/{wheel.name}", compress_type=zipfile.ZIP_STORED)
        os.replace(partial, path)
    return path


def main(argv: list[str] | None = None) -> int:
    """Build the zip; print its path and size."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "dist"), help="folder of the zip (default: dist/)")
    parser.add_argument("--platform", choices=sorted(PLATFORMS), help="default: this machine's")
    parser.add_argument(
        "--numpy", default=DEFAULT_NUMPY, help=f"NumPy of the Blender targeted (default {DEFAULT_NUMPY})"
    )
    args = parser.parse_args(argv)
    path = build(Path(args.out), args.platform or host_platform(), args.numpy)
    print(f"{path} ({path.stat().st_size / 2**20:.0f} MiB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
