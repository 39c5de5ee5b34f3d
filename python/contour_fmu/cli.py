"""Plumbing: the command line `contour-fmu` (the console script of python/pyproject.toml),
one command per runner, each with its module's own arguments (`contour-fmu COMMAND --help`).

    contour-fmu demo [...]                 = python -m contour_fmu.demo
    contour-fmu campaign run|replay [...]  = python -m contour_fmu.campaign
    contour-fmu libcosim [...]             = python -m contour_fmu.engines.libcosim
    contour-fmu ecos [...]                 = python -m contour_fmu.engines.ecos

A command whose extra is not installed says which one to install (exit status 2).
"""

import argparse
import importlib
import sys

from .extras import MissingExtra

PROG = "contour-fmu"

# command -> (module, what it does)
COMMANDS = {
    "demo": ("contour_fmu.demo.__main__",
             "the paper's comparison through the FMUs: tables, CSV and plots (extras plots, "
             "reference)"),
    "campaign": ("contour_fmu.campaign.__main__",
                 "run | replay a campaign of closed-loop runs on Dask (extra campaign)"),
    "libcosim": ("contour_fmu.engines.libcosim",
                 "a closed loop in libcosim, printed as JSON (extra engines)"),
    "ecos": ("contour_fmu.engines.ecos", "a closed loop in ecos, printed as JSON (extra engines)"),
}


def parser():
    listing = "\n".join(f"  {name:10} {what}" for name, (_, what) in COMMANDS.items())
    p = argparse.ArgumentParser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Run the contour-fmu FMUs (cross-coupled contour control, FMI 2.0 "
                    "Co-Simulation) in Python.",
        epilog=f"commands:\n{listing}\n\n`{PROG} COMMAND --help` gives a command's arguments.")
    p.add_argument("command", choices=COMMANDS, metavar="COMMAND", help="one of the commands below")
    p.add_argument("arguments", nargs="*", default=[], metavar="ARGUMENT", help="the command's arguments")
    return p


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    command = parser().parse_args(argv[:1]).command  # --help, or a command's name
    prog = f"{PROG} {command}"
    try:
        module = importlib.import_module(COMMANDS[command][0])
        result = module.main(argv[1:], prog=prog)
    except MissingExtra as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    return result if isinstance(result, int) else 0


if __name__ == "__main__":
    sys.exit(main())
