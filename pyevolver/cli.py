"""Command-line interface that behaves like ``evolver``.

``pyevolver FILE.fe`` loads the datafile (running its ``read`` section) and
then reads commands from the terminal (prompt ``Enter command: ``) or from
standard input when it is not a terminal; ``-f FILE`` runs a command file
after loading.  Errors become messages and exit codes here only.
"""
from __future__ import annotations

import argparse
import os
import sys

from . import __version__
from .commands import interpreter as I
from .errors import PyEvolverError
from .session import Session

PROMPT = "Enter command: "
MORE = "more> "


def build_parser():
    p = argparse.ArgumentParser(
        prog="pyevolver",
        description="Surface Evolver datafiles and command scripts in Python.")
    p.add_argument("datafile", help="Surface Evolver datafile (.fe)")
    p.add_argument("-f", dest="command_file", help="command file to run after loading")
    p.add_argument("-p", dest="threads", type=int, default=1,
                   help="accepted for compatibility with evolver (ignored)")
    p.add_argument("--version", action="version", version=f"pyevolver {__version__}")
    return p


def _find_datafile(name):
    if os.path.isfile(name):
        return name
    if not name.endswith(".fe") and os.path.isfile(name + ".fe"):
        return name + ".fe"
    return None


def main(argv=None):
    try:
        return _main(argv)
    except BrokenPipeError:
        # the reader of our output went away (e.g. `| head`): exit quietly
        try:
            sys.stdout = open(os.devnull, "w")
        except OSError:
            pass
        return 0


def _main(argv=None):
    args = build_parser().parse_args(argv)
    path = _find_datafile(args.datafile)
    if path is None:
        sys.stderr.write(f"pyevolver: cannot open datafile '{args.datafile}': no such file\n")
        return 1
    try:
        session = Session.load(path)
    except PyEvolverError as exc:
        sys.stderr.write(f"{exc}\n")
        return 1
    try:
        if args.command_file:
            try:
                with open(args.command_file, encoding="latin-1") as fh:
                    text = fh.read()
            except OSError as exc:
                sys.stderr.write(f"pyevolver: cannot read command file "
                                 f"'{args.command_file}': {exc.strerror}\n")
                return 1
            session.run(text, where=args.command_file, stop_on_error=False)
        return repl(session)
    except I.Quit as q:
        sys.stdout.flush()
        return q.code


def repl(session, stdin=None):
    """Read commands until ``q`` or end of input; returns the exit code."""
    stdin = stdin or sys.stdin
    interactive = stdin.isatty()
    buf = ""
    lineno = 0
    while True:
        if interactive:
            sys.stdout.write(MORE if buf else PROMPT)
            sys.stdout.flush()
        try:
            line = stdin.readline()
        except KeyboardInterrupt:
            sys.stdout.write("\n")
            buf = ""
            continue
        if not line:
            if buf.strip():
                _run(session, buf, lineno)
            return 0
        lineno += 1
        buf += line
        if not I.needs_more(buf):
            try:
                _run(session, buf, lineno)
            finally:
                buf = ""


def _run(session, text, lineno):
    try:
        session.run(text, where="<stdin>", line=max(1, lineno - text.count("\n") + 1),
                    stop_on_error=False)
    except KeyboardInterrupt:
        sys.stdout.write("\nInterrupted.\n")
    sys.stdout.flush()


if __name__ == "__main__":   # pragma: no cover
    sys.exit(main())
