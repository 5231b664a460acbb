"""The ``radar`` command line.

    radar simulate --scene SCENE.json|table1 --out ADC.npy
    radar detect   --scene SCENE.json|table1 --json OUT.json [--backend model|float|rtl]
    radar demo     [--out DIR] [--preset full|paper-fpga]
    radar capture  --scene ... --out FILE.dmacap      (DMA packets of simulated frames)
    radar replay   --capture FILE.dmacap --port P     (send as the board would, over UDP)
    radar receive  --port P --preset ... --json OUT   (decode UDP packets -> point cloud)
    radar view     --replay F | --udp-port P | --scene S   (live browser view)
    radar mcap info FILE.mcap                         (summarise an --mcap recording)
    radar gnn      dataset|train|eval|detect ...      (the GNN object detector)
    radar profile  show NAME|FILE.toml|FILE.cfg       (a radar profile's derived numbers)
    radar process  --radar PROFILE --capture FILE --json OUT   (a capture -> point cloud)
    radar curves   [--quick] [--ray-address ADDR] --json OUT [--plots DIR]   (Pd, CRB curves)
    radar calibrate --radar PROFILE --capture FILE --reflector R[,AZ[,EL]] --out CAL.json

One module per command group under :mod:`radar.commands`. Bad input ends with exit status 2
and a one-line reason on stderr. ``radar <cmd> --help`` explains every option.
"""

from __future__ import annotations

import argparse
import os
import sys

from model.config import PRESETS
from radar.commands import (
    calibrate,
    curves,
    demo,
    detect,
    gnn,
    link,
    mcap,
    process,
    profile,
    simulate,
    view,
)
from radar.common import CliError

COMMAND_GROUPS = (simulate, detect, demo, link, view, mcap, profile, process, calibrate,
                  curves)
"""Command modules, each with ``add_parsers(sub, presets)``, in ``--help`` order."""


def build_parser(with_gnn: bool = False) -> argparse.ArgumentParser:
    """The ``radar`` parser; the ``gnn`` subcommands only if ``with_gnn``."""
    p = argparse.ArgumentParser(
        prog="radar",
        description="Open 77 GHz FMCW TDM-MIMO radar array processor: scene simulator, "
                    "reference of the FPGA chain, host processing and DMA stream tools.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    presets = sorted(PRESETS)
    for group in COMMAND_GROUPS:
        group.add_parsers(sub, presets)
    gnn.add_parsers(sub, presets, with_subcommands=with_gnn)
    return p


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser(with_gnn=bool(argv) and argv[0] == "gnn")
    args = parser.parse_args(argv)
    try:
        return int(args.func(args))
    except CliError as exc:
        print(f"radar {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader went away (`radar ... | head`): not an error of ours; stdout goes to
        # /dev/null so the interpreter's final flush cannot raise again
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:
        print(f"radar {args.command}: error: {exc.strerror or exc}: "
              f"{getattr(exc, 'filename', '') or ''}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"radar {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
