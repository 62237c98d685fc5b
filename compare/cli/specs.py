"""``spindle-verify specs``: list the shipped spindle descriptions."""

from __future__ import annotations

import argparse


def _cmd_specs(args: argparse.Namespace) -> int:
    from spindle.spec_reader import load_spec, shipped_specs

    for name, path in sorted(shipped_specs().items()):
        spec = load_spec(path)
        print(f"{name:12s} {spec.description}")
        print(f"{'':12s} {path}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    sp = subparsers.add_parser("specs", help="list the shipped spindle descriptions")
    sp.set_defaults(func=_cmd_specs)
