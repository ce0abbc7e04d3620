"""Build the hand-written third-party FMUs in ``tests/thirdparty`` with plain gcc.

Deliberately independent of ``fmu_build/`` (and of ``twin``): the point of these FMUs is to
show that ``twin`` runs FMI Co-Simulation FMUs it did not generate.  Only the standard FMI 2.0
and 3.0 headers are taken from fmpy's ``c-code`` directory.

* ``vanderpol/``: a Van der Pol oscillator (FMI 2.0).
* ``typecov/``: the type-coverage models, each built for FMI 2.0 and FMI 3.0 from one C
  source: ``AllTypes`` (inputs, outputs and parameters of every type, a resource file),
  ``Staircase`` (time events, ends its own experiment) and ``Ball`` (state events, units
  through type definitions).

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
TYPECOV_DIR = HERE / "typecov"
TYPECOV_MODELS = ("AllTypes", "Staircase", "Ball")
#: binaries/ folder per FMI version on x86-64 Linux
_PLATFORM = {2: "linux64", 3: "x86_64-linux"}


def fmi_headers() -> Path:
    """Directory holding ``fmi2Functions.h`` & co. (shipped with fmpy)."""
    import fmpy
    path = Path(fmpy.__file__).parent / "c-code"
    for header in ("fmi2Functions.h", "fmi3Functions.h"):
        if not (path / header).exists():
            raise FileNotFoundError(f"FMI header {header} not found in {path}")
    return path


def _gcc() -> str:
    gcc = shutil.which("gcc")
    if gcc is None:
        raise RuntimeError("gcc not found on PATH; it is needed to build the third-party test FMUs")
    return gcc


def _compile(sources: list[Path], so: Path, defines: tuple[str, ...] = ()) -> None:
    cmd = [_gcc(), "-shared", "-fPIC", "-O2", "-std=c99", "-Wall", "-Wextra", "-fvisibility=hidden",
           *(f"-D{d}" for d in defines), f"-I{fmi_headers()}", "-o", str(so), *map(str, sources), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"gcc failed ({proc.returncode}):\n{' '.join(cmd)}\n{proc.stderr}")


def build_typecov(model: str, fmi_version: int, out_dir: Path) -> Path:
    """Compile one type-coverage model for FMI ``fmi_version`` (2 or 3) into ``<out_dir>/<model>.fmu``.

    The archive holds ``modelDescription.xml``, the binary for this platform, ``sources/`` and,
    for ``AllTypes``, ``resources/message.txt``.  Returns the FMU path.
    """
    if model not in TYPECOV_MODELS:
        raise ValueError(f"unknown type-coverage model {model!r}; known: {', '.join(TYPECOV_MODELS)}")
    if fmi_version not in _PLATFORM:
        raise ValueError(f"fmi_version must be 2 or 3, got {fmi_version!r}")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    sources = [TYPECOV_DIR / f"{model}.c", TYPECOV_DIR / "core.c", TYPECOV_DIR / f"fmi{fmi_version}_slave.c"]
    headers = [TYPECOV_DIR / "slave.h", TYPECOV_DIR / "core.h"]
    fmu = out_dir / f"{model}.fmu"
    with tempfile.TemporaryDirectory(prefix=f"{model}_") as tmp:
        so = Path(tmp) / f"{model}.so"
        _compile(sources, so, (f"FMI_VERSION={fmi_version}",))
        partial = out_dir / f"{model}.fmu.part"
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as zf:
            zf.write(TYPECOV_DIR / f"{model}.fmi{fmi_version}.xml", "modelDescription.xml")
            zf.write(so, f"binaries/{_PLATFORM[fmi_version]}/{model}.so")
            for f in sources + headers:
                zf.write(f, f"sources/{f.name}")
            if model == "AllTypes":
                zf.write(TYPECOV_DIR / "resources" / "message.txt", "resources/message.txt")
        partial.replace(fmu)
    return fmu


def build_vanderpol(out_dir: Path) -> Path:
    """Compile ``vanderpol/VanDerPol.c`` and package ``<out_dir>/VanDerPol.fmu``; return its path.

    The archive holds ``modelDescription.xml``, ``binaries/linux64/VanDerPol.so`` and
    ``sources/VanDerPol.c``.  Raises ``RuntimeError`` when gcc is missing or fails.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    source = VANDERPOL_DIR / "VanDerPol.c"
    description = VANDERPOL_DIR / "modelDescription.xml"
    fmu = out_dir / "VanDerPol.fmu"
    with tempfile.TemporaryDirectory(prefix="vanderpol_") as tmp:
        so = Path(tmp) / "VanDerPol.so"
        _compile([source], so)
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
    out = Path(args[0])
    print(build_vanderpol(out))
    for version in (2, 3):
        for model in TYPECOV_MODELS:
            print(build_typecov(model, version, out / f"fmi{version}"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
