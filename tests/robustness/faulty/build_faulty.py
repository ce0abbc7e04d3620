"""Build the deliberately failing test FMU (``Faulty.c``) and broken copies of it with plain gcc.

* ``Faulty.fmu``: fails on request (parameter ``fault``, see ``Faulty.c``);
* ``FaultyWrongGUID.fmu``: its model description names another GUID, so ``fmi2Instantiate``
  returns NULL;
* ``FaultyTruncated.fmu``: its shared library is cut to a quarter of its size.

Usage::

    python tests/robustness/faulty/build_faulty.py OUT_DIR
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
GUID = "{5f1b7e2a-2c1d-4f57-9f3e-7d8a0c6b4e11}"


def _headers() -> Path:
    import fmpy
    path = Path(fmpy.__file__).parent / "c-code"
    if not (path / "fmi2Functions.h").exists():
        raise FileNotFoundError(f"FMI 2.0 headers not found in {path}")
    return path


def _package(out: Path, description: str, so: bytes) -> Path:
    part = out.with_suffix(".fmu.part")
    with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("modelDescription.xml", description)
        zf.writestr("binaries/linux64/Faulty.so", so)
        zf.write(HERE / "Faulty.c", "sources/Faulty.c")
    part.replace(out)
    return out


def build_faulty(out_dir: Path) -> dict[str, Path]:
    """Compile and package the three FMUs into ``out_dir``; name -> path.  RuntimeError without gcc."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    gcc = shutil.which("gcc")
    if gcc is None:
        raise RuntimeError("gcc not found on PATH; it is needed to build the faulty test FMU")
    with tempfile.TemporaryDirectory(prefix="faulty_") as tmp:
        so_path = Path(tmp) / "Faulty.so"
        cmd = [gcc, "-shared", "-fPIC", "-O1", "-std=c99", "-Wall", f"-I{_headers()}", "-o", str(so_path),
               str(HERE / "Faulty.c"), "-lm"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"gcc failed ({proc.returncode}):\n{' '.join(cmd)}\n{proc.stderr}")
        so = so_path.read_bytes()
    description = (HERE / "modelDescription.xml").read_text()
    return {
        "faulty": _package(out_dir / "Faulty.fmu", description, so),
        "wrong_guid": _package(out_dir / "FaultyWrongGUID.fmu",
                               description.replace(GUID, "{00000000-0000-0000-0000-000000000000}"), so),
        "truncated": _package(out_dir / "FaultyTruncated.fmu", description, so[: len(so) // 4]),
    }


if __name__ == "__main__":
    if len(sys.argv) != 2:
        print("usage: python tests/robustness/faulty/build_faulty.py OUT_DIR", file=sys.stderr)
        sys.exit(2)
    for name, path in build_faulty(Path(sys.argv[1])).items():
        print(name, path)
