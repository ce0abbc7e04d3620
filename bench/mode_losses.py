"""Where a calibration loses the rig's first six modes, from what `bench/calibration_rigs.py` wrote.

    python bench/mode_losses.py OUT [OUT ...]

For each of the rig's first six observable modes of each gearbox in OUT/results.json (its
``first6_explained`` rows), one class, in this order:

* ``met``: the calibrated twin's nearest visible mode within 3 % (``met (slot)`` when it is a
  sensor-path slot, a match by construction);
* ``not seen``: no mode `twin calibrate` used (``<rig>_<seed>_cal/modes.json``, confidence at least
  :data:`twin.modes.MIN_CONFIDENCE`) within 2 %;
* ``seen, unpaired``: seen, but not among the measured modes paired with a model mode at the
  nominal set (``sensitivity.json``, ``measured_hz``): the fit never worked on it;
* ``paired, not reached``: paired at the nominal set, and the fit did not bring a visible twin mode
  within 3 %.

Prints one Markdown row per OUT. Reads files only; no simulation.
"""
from __future__ import annotations

import json
import sys
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

CLASSES = ("met", "met (slot)", "not seen", "seen, unpaired", "paired, not reached")
MET_PC, SEEN_PC = 3.0, 2.0


def loss_class(mode: dict, used_hz, paired_hz) -> str:
    """The class of one explained first-six mode (``hz``, ``error_pc``, ``twin_class``) given the
    measured modes the calibration used and those it paired at the nominal set [Hz]."""
    if abs(mode["error_pc"]) <= MET_PC:
        return "met (slot)" if mode["twin_class"] == "sensor path" else "met"

    def near(values):
        return any(abs(f / mode["hz"] - 1) * 100 <= SEEN_PC for f in values)
    if not near(used_hz):
        return "not seen"
    return "paired, not reached" if near(paired_hz) else "seen, unpaired"


def losses(out: Path) -> Counter:
    """Counts of :data:`CLASSES` over every gearbox in ``out``."""
    from twin.modes import MIN_CONFIDENCE
    counts = Counter({c: 0 for c in CLASSES})
    for row in json.loads((out / "results.json").read_text()):
        cal = out / f"{row['rig']}_{row['seed']}_cal"
        used = [m["frequency_hz"] for m in json.loads((cal / "modes.json").read_text())["modes"]
                if m["confidence"] >= MIN_CONFIDENCE]
        paired = json.loads((cal / "sensitivity.json").read_text())["measured_hz"]
        for mode in row["first6_explained"]:
            counts[loss_class(mode, used, paired)] += 1
    return counts


def read_run(out: Path) -> list | None:
    """The gearboxes of OUT/results.json as `bench/calibration_rigs.py` wrote them, or None with a
    one-line error on stderr naming what is missing (for the scripts that read a finished run)."""
    try:
        return json.loads((Path(out) / "results.json").read_text())
    except (OSError, ValueError) as exc:
        print(f"error: {out}: not a finished calibration_rigs run ({type(exc).__name__}: {exc})", file=sys.stderr)
        return None


def main(argv=None) -> int:
    outs = [Path(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not outs:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    rows = ["| out | " + " | ".join(CLASSES) + " |", "|---|" + "---|" * len(CLASSES)]
    for out in outs:
        try:
            c = losses(out)
        except (OSError, KeyError, ValueError) as exc:      # not a finished bench run: name what is missing
            print(f"error: {out}: not a finished calibration_rigs run ({type(exc).__name__}: {exc})", file=sys.stderr)
            return 2
        rows.append(f"| {out.name} | " + " | ".join(str(c[k]) for k in CLASSES) + " |")
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
