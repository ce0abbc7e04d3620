"""Build the hand-written third-party FMU(s) in ``tests/thirdparty`` with plain gcc.

Deliberately independent of ``fmu_build/`` (and of ``twin``): the point of these FMUs is to
show that the orchestrator runs FMI 2.0 Co-Simulation FMUs it did not generate.  Only the
standard FMI 2.0 headers are taken from fmpy's ``c-code`` directory.

Usage::

    python tests/thirdparty/build_thirdparty.py build/thirdparty
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
VANDERPOL_DIR = HERE / "vanderpol"


def fmi_headers() -> Path:
    """Directory holding ``fmi2Functions.h`` & co. (shipped with fmpy)."""
    import fmpy
    path = Path(fmpy.__file__).parent / "c-code"
    if not (path / "fmi2Functions.h").exists():
        raise FileNotFoundError(f"FMI 2.0 headers not found in {path}")
    return path


def build_vanderpol(out_dir: Path) -> Path:
    """Compile ``vanderpol/VanDerPol.c`` and package ``<out_dir>/VanDerPol.fmu``; return its path.

    The archive holds ``modelDescription.xml``, ``binaries/linux64/VanDerPol.so`` and
    ``sources/VanDerPol.c``.  Raises ``RuntimeError`` when gcc is missing or fails.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    gcc = shutil.which("gcc")
    if gcc is None:
        raise RuntimeError("gcc not found on PATH; it is needed to build the third-party test FMU")
    source = VANDERPOL_DIR / "VanDerPol.c"
    description = VANDERPOL_DIR / "modelDescription.xml"
    fmu = out_dir / "VanDerPol.fmu"
    with tempfile.TemporaryDirectory(prefix="vanderpol_") as tmp:
        so = Path(tmp) / "VanDerPol.so"
        cmd = [gcc, "-shared", "-fPIC", "-O2", "-std=c99", "-Wall", "-Wextra", "-fvisibility=hidden",
               f"-I{fmi_headers()}", "-o", str(so), str(source), "-lm"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"gcc failed ({proc.returncode}):\n{' '.join(cmd)}\n{proc.stderr}")
        partial = out_dir / "VanDerPol.fmu.part"
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.write(description, "modelDescription.xml")
            zf.write(so, "binaries/linux64/VanDerPol.so")
            zf.write(source, "sources/VanDerPol.c")
        partial.replace(fmu)
    return fmu


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python tests/thirdparty/build_thirdparty.py OUT_DIR", file=sys.stderr)
        return 2
    print(build_vanderpol(Path(args[0])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
