"""Command line of the beam rig: python -m rigs.beam steady|runup|stages|impact|modes ..."""
from __future__ import annotations

import argparse
import json
import sys

from .effects import DEFAULTS, EffectError
from .hammer import DIRECTIONS, LOCATIONS, HammerError
from .io import WriteError, write
from .rig import Rig, RigError
from .simulate import DamageError


def _box(args) -> Rig:
    rig = Rig()
    return rig.scattered(args.box, args.scatter) if args.box is not None else rig


def _damage(args):
    d = {}
    if args.pitting:
        d["pitting"] = args.pitting
    if args.wear:
        d["wear"] = args.wear
    return d or None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m rigs.beam", description=__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--box", type=int, default=None,
                        help="gearbox seed: base parameters scattered (default: the nominal gearbox)")
    common.add_argument("--scatter", type=float, default=0.12, help="+- scatter of a --box gearbox")
    common.add_argument("--seed", type=int, default=0, help="record seed")
    rec = argparse.ArgumentParser(add_help=False, parents=[common])
    rec.add_argument("--load", type=float, default=20.0, help="brake torque [N m]")
    rec.add_argument("--effect", choices=sorted(DEFAULTS), default=None)
    rec.add_argument("--pitting", type=float, default=0.0, help="pitted flank fraction")
    rec.add_argument("--wear", type=float, default=0.0, help="mean worn depth [m]")
    rec.add_argument("--out", required=True, help="output .h5 (truth beside it as .h5.truth.json)")
    st = sub.add_parser("steady", parents=[rec], help="one steady record")
    st.add_argument("--speed", type=float, default=20.0, help="pinion speed [Hz]")
    st.add_argument("--duration", type=float, default=2.0)
    ru = sub.add_parser("runup", parents=[rec], help="one run-up record")
    ru.add_argument("--from", dest="v0", type=float, default=2.0)
    ru.add_argument("--to", dest="v1", type=float, default=20.0)
    ru.add_argument("--duration", type=float, default=6.0)
    sg = sub.add_parser("stages", parents=[common], help="damage-stage records (pitting or wear)")
    sg.add_argument("--kind", choices=("pitting", "wear"), required=True)
    sg.add_argument("--per-stage", type=int, default=4)
    sg.add_argument("--duration", type=float, default=1.0)
    sg.add_argument("--at-centre", action="store_true", help="damage at stage centres")
    sg.add_argument("--out", required=True)
    im = sub.add_parser("impact", parents=[common], help="one hammer-test record (force channel hammer)")
    im.add_argument("--speed", type=float, default=20.0, help="pinion speed [Hz] (0.5: slow roll)")
    im.add_argument("--load", type=float, default=20.0, help="brake torque [N m]")
    im.add_argument("--duration", type=float, default=4.0)
    im.add_argument("--rate", type=float, default=4.0, help="mean blows per second")
    im.add_argument("--location", choices=LOCATIONS, default="pinion_housing")
    im.add_argument("--direction", choices=tuple(DIRECTIONS), default="vertical",
                    help="struck from above (-z) or from the side (-y)")
    im.add_argument("--out", required=True, help="output .h5 (truth beside it as .h5.truth.json)")
    md = sub.add_parser("modes", parents=[common], help="modes of the linearised rig")
    md.add_argument("--load", type=float, default=20.0)
    md.add_argument("--fmax", type=float, default=5000.0)
    md.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    try:
        rig = _box(args)
        if args.cmd == "modes":
            modes = rig.modes(20.0, args.load, args.fmax)
            if args.json:
                print(json.dumps([m.__dict__ for m in modes], indent=1))
            else:
                for m in modes:
                    print(f"{m.frequency:9.1f} Hz  zeta {m.damping_ratio:.4f}  obs {m.observability:.3f}  {m.label}")
            return 0
        if args.cmd == "steady":
            recs = [rig.steady(args.speed, args.load, args.duration, args.effect, _damage(args), args.seed)]
        elif args.cmd == "runup":
            recs = [rig.runup((args.v0, args.v1), args.load, args.duration, args.effect, _damage(args),
                              args.seed)]
        elif args.cmd == "impact":
            recs = [rig.impact(args.speed, args.load, args.duration, args.rate, args.location,
                               args.seed, direction=args.direction)]
        else:
            fn = rig.pitting_stages if args.kind == "pitting" else rig.wear_stages
            recs = fn(args.per_stage, args.duration, args.seed, args.at_centre)
        path = write(args.out, recs)
        print(f"wrote {len(recs)} record(s) to {path} and {path}.truth.json")
        return 0
    except (RigError, EffectError, DamageError, HammerError, WriteError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
