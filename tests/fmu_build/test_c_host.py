"""The Gearbox21 FMU driven by a plain C host (dlopen/dlsym only, no FMI library).

Proves the binary works outside fmpy, that the variadic logger callback and the memory
callbacks are honoured, and that the C sources shipped in the FMU rebuild an equivalent binary.
"""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from fmu_build.build import CFLAGS

pytestmark = pytest.mark.needs_gcc

STEP, STOP = 1e-3, 0.01       # communication step and stop time [s]

HOST_C = r"""
/* Minimal FMI 2.0 Co-Simulation host.
 * usage: host LIBRARY GUID RESOURCE_URI VALUE_REFERENCE STEP STOP
 * prints "t value" after every doStep, with 17 significant digits (exact round trip). */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi2Functions.h"

/* FMI 2.0 logger: printf-style message with variadic arguments. */
static void logger(fmi2ComponentEnvironment env, fmi2String instance, fmi2Status status,
                   fmi2String category, fmi2String message, ...) {
    va_list ap;
    (void)env;
    fprintf(stderr, "[%s] status=%d category=%s: ", instance ? instance : "?", (int)status,
            category ? category : "?");
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static void *resolve(void *lib, const char *name) {
    void *f = dlsym(lib, name);
    if (!f) { fprintf(stderr, "missing symbol %s\n", name); exit(3); }
    return f;
}

int main(int argc, char **argv) {
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2ValueReference vr;
    fmi2Component c;
    double h, stop, t = 0.0, value;
    long k, n;
    void *lib;
    fmi2InstantiateTYPE *instantiate;
    fmi2SetupExperimentTYPE *setup_experiment;
    fmi2EnterInitializationModeTYPE *enter_initialization;
    fmi2ExitInitializationModeTYPE *exit_initialization;
    fmi2DoStepTYPE *do_step;
    fmi2GetRealTYPE *get_real;
    fmi2TerminateTYPE *terminate;
    fmi2FreeInstanceTYPE *free_instance;

    if (argc != 7) { fprintf(stderr, "usage: host LIBRARY GUID RESOURCE_URI VR STEP STOP\n"); return 2; }
    vr = (fmi2ValueReference)strtoul(argv[4], NULL, 10);
    h = strtod(argv[5], NULL);
    stop = strtod(argv[6], NULL);
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 3; }
    instantiate = (fmi2InstantiateTYPE *)resolve(lib, "fmi2Instantiate");
    setup_experiment = (fmi2SetupExperimentTYPE *)resolve(lib, "fmi2SetupExperiment");
    enter_initialization = (fmi2EnterInitializationModeTYPE *)resolve(lib, "fmi2EnterInitializationMode");
    exit_initialization = (fmi2ExitInitializationModeTYPE *)resolve(lib, "fmi2ExitInitializationMode");
    do_step = (fmi2DoStepTYPE *)resolve(lib, "fmi2DoStep");
    get_real = (fmi2GetRealTYPE *)resolve(lib, "fmi2GetReal");
    terminate = (fmi2TerminateTYPE *)resolve(lib, "fmi2Terminate");
    free_instance = (fmi2FreeInstanceTYPE *)resolve(lib, "fmi2FreeInstance");

    c = instantiate("c_host", fmi2CoSimulation, argv[2], argv[3], &callbacks, fmi2False, fmi2False);
    if (!c) { fprintf(stderr, "fmi2Instantiate failed\n"); return 4; }
    if (setup_experiment(c, fmi2False, 0.0, 0.0, fmi2True, stop) != fmi2OK) return 5;
    if (enter_initialization(c) != fmi2OK || exit_initialization(c) != fmi2OK) return 5;
    n = (long)(stop / h + 0.5);
    for (k = 0; k < n; k++) {
        if (do_step(c, t, h, fmi2True) != fmi2OK) { fprintf(stderr, "fmi2DoStep failed at t=%g\n", t); return 6; }
        t = (double)(k + 1) * h;
        if (get_real(c, &vr, 1, &value) != fmi2OK) return 7;
        printf("%.17g %.17g\n", t, value);
    }
    terminate(c);
    free_instance(c);
    dlclose(lib);
    return 0;
}
"""


@pytest.fixture(scope="module")
def gearbox(gearbox_fmu, unzip_fmu, tmp_path_factory):
    """(model description, unzip dir, compiled host executable)."""
    md, unzipped = unzip_fmu(gearbox_fmu)
    work = tmp_path_factory.mktemp("c_host")
    (work / "host.c").write_text(HOST_C)
    host = work / "host"
    # the FMI headers come from the FMU's own sources/ directory
    proc = subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-I", str(unzipped / "sources"),
                           "-o", str(host), str(work / "host.c"), "-ldl"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return md, unzipped, host


def _run_host(host: Path, library: Path, guid: str, unzipped: Path, vr: int) -> subprocess.CompletedProcess:
    return subprocess.run([str(host), str(library), guid, (unzipped / "resources").as_uri(), str(vr),
                           repr(STEP), repr(STOP)], capture_output=True, text=True, timeout=60)


def _parse(stdout: str) -> tuple[np.ndarray, np.ndarray]:
    values = np.array([[float(w) for w in line.split()] for line in stdout.splitlines()])
    return values[:, 0], values[:, 1]


def _fmpy_mesh_force(open_slave, fmu: Path) -> np.ndarray:
    slave, vr = open_slave(fmu)
    out = []
    for k in range(round(STOP / STEP)):
        slave.doStep(k * STEP, STEP)
        out.append(slave.getReal([vr["mesh_force"]])[0])
    return np.array(out)


def _mesh_force_vr(md) -> int:
    (vr,) = [v.valueReference for v in md.modelVariables if v.name == "mesh_force"]
    return vr


def test_c_host_runs_the_gearbox_like_fmpy(gearbox, gearbox_fmu, open_slave):
    md, unzipped, host = gearbox
    library = unzipped / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    proc = _run_host(host, library, md.guid, unzipped, _mesh_force_vr(md))
    assert proc.returncode == 0, proc.stderr
    t, mesh_force = _parse(proc.stdout)
    assert t == pytest.approx(STEP * np.arange(1, 11), rel=1e-15)
    reference = _fmpy_mesh_force(open_slave, gearbox_fmu)
    assert np.all(np.isfinite(mesh_force)) and np.abs(mesh_force).max() > 1.0   # a loaded mesh [N]
    assert np.allclose(mesh_force, reference, rtol=1e-9, atol=0.0)


def test_c_host_wrong_guid_is_refused_through_the_logger(gearbox):
    md, unzipped, host = gearbox
    library = unzipped / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    wrong = "{00000000-0000-0000-0000-000000000000}"
    proc = _run_host(host, library, wrong, unzipped, _mesh_force_vr(md))
    assert proc.returncode == 4
    # the variadic arguments were formatted: both GUIDs appear in the message
    assert f"GUID {wrong} does not match this binary ({md.guid})" in proc.stderr
    assert "status=3" in proc.stderr


def test_shipped_sources_rebuild_an_equivalent_binary(gearbox, gearbox_fmu, open_slave, tmp_path):
    md, unzipped, host = gearbox
    sources = unzipped / "sources"
    library = tmp_path / "rebuilt.so"
    proc = subprocess.run(["gcc", *CFLAGS, "-I", str(sources), "-o", str(library),
                           *sorted(str(p) for p in sources.glob("*.c")), "-lm"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    run = _run_host(host, library, md.guid, unzipped, _mesh_force_vr(md))
    assert run.returncode == 0, run.stderr
    _, mesh_force = _parse(run.stdout)
    assert np.allclose(mesh_force, _fmpy_mesh_force(open_slave, gearbox_fmu), rtol=1e-9, atol=0.0)
