"""Command line of the pedestal rig.

    python -m rigs.pedestal steady --seed 0 --out steady.h5 [--speed 20 --load 20 --duration 2]
    python -m rigs.pedestal runup  --seed 0 --out runup.h5  [--from 2 --to 20 --duration 6]
    python -m rigs.pedestal stages --kind pitting --per-stage 4 --seed 0 --out pitting.h5
    python -m rigs.pedestal impact --seed 0 --out impact.h5
    python -m rigs.pedestal modes  [--json modes.json]

``--gearbox N`` picks a scattered gearbox (``Rig().scattered(N, --scatter)``), otherwise the
nominal one. Every file gets its ``.truth.json`` beside it.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from .effects import EFFECTS
from .record import Damage
from .rig import VERSION, Rig


class CliError(Exception):
    """A bad command-line value."""


def _damage(text: str | None) -> Damage | None:
    if text is None:
        return None
    kind, sep, size = text.partition(":")
    if not sep:
        raise CliError(f"--damage must be KIND:SIZE (pitting:0.08 or wear:60e-6), got {text!r}")
    try:
        return Damage(kind, float(size))
    except (TypeError, ValueError) as exc:
        raise CliError(f"--damage {text!r}: {exc}") from None


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m rigs.pedestal", description=VERSION)
    sub = p.add_subparsers(dest="command", required=True)

    def common(sp, out=True):
        sp.add_argument("--gearbox", type=int, default=None,
                        help="seed of a scattered gearbox (default: the nominal gearbox)")
        sp.add_argument("--scatter", type=float, default=0.12)
        sp.add_argument("--seed", type=int, default=0, help="record seed")
        if out:
            sp.add_argument("--out", required=True, help="output .h5 (truth beside it)")

    for name in ("steady", "runup"):
        sp = sub.add_parser(name)
        common(sp)
        sp.add_argument("--load", type=float, default=20.0, help="brake torque [N.m]")
        sp.add_argument("--duration", type=float, default=2.0 if name == "steady" else 6.0)
        sp.add_argument("--effect", choices=EFFECTS, default=None)
        sp.add_argument("--damage", default=None, help="KIND:SIZE, pitting:0.08 or wear:60e-6")
        sp.add_argument("--dry", action="store_true", help="dry mesh friction")
        if name == "steady":
            sp.add_argument("--speed", type=float, default=20.0, help="pinion speed [Hz]")
        else:
            sp.add_argument("--from", dest="start", type=float, default=2.0)
            sp.add_argument("--to", dest="end", type=float, default=20.0)
    sp = sub.add_parser("stages")
    common(sp)
    sp.add_argument("--kind", choices=("pitting", "wear"), required=True)
    sp.add_argument("--per-stage", type=int, default=4)
    sp.add_argument("--duration", type=float, default=1.0)
    sp = sub.add_parser("impact")
    common(sp)
    sp.add_argument("--speed", type=float, default=20.0)
    sp.add_argument("--load", type=float, default=20.0)
    sp.add_argument("--duration", type=float, default=4.0)
    sp.add_argument("--location", default="pinion_pedestal")
    sp.add_argument("--direction", default="vertical", help="struck from above (vertical) or from the side (horizontal)")
    sp = sub.add_parser("modes")
    common(sp, out=False)
    sp.add_argument("--speed", type=float, default=20.0)
    sp.add_argument("--load", type=float, default=20.0)
    sp.add_argument("--effect", choices=EFFECTS, default=None)
    sp.add_argument("--json", default=None)
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from .io import write
    from .modes import mode_table
    try:
        rig = Rig() if args.gearbox is None else Rig().scattered(args.gearbox, args.scatter)
        if getattr(args, "out", None):
            out = Path(args.out)
            if out.suffix.lower() not in (".h5", ".hdf5"):
                raise CliError(f"--out must end in .h5 or .hdf5, got {args.out!r}")
            if not out.parent.is_dir():
                raise CliError(f"--out directory does not exist: {str(out.parent)!r}")
        t0 = time.perf_counter()
        if args.command == "modes":
            modes = rig.modes(args.speed, args.load, effect=args.effect)
            print(mode_table(modes, count=len(modes)))
            if args.json:
                Path(args.json).write_text(json.dumps([m.as_dict() for m in modes], indent=1))
            return 0
        if args.command == "steady":
            recs = [rig.steady(args.speed, args.load, args.duration, args.effect,
                               _damage(args.damage), args.seed, lubricated=not args.dry)]
        elif args.command == "runup":
            recs = [rig.runup((args.start, args.end), args.load, args.duration, args.effect,
                              _damage(args.damage), args.seed, lubricated=not args.dry)]
        elif args.command == "impact":
            recs = [rig.impact(args.speed, args.load, args.duration, location=args.location,
                               seed=args.seed, direction=args.direction)]
        else:
            recs = rig.stage_records(args.kind, args.per_stage, args.duration, args.seed)
        write(args.out, recs)
        print(f"{args.out}: {len(recs)} record(s), truth in {args.out}.truth.json "
              f"({time.perf_counter() - t0:.1f} s)")
        return 0
    except (CliError, ValueError, TypeError, FileNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
