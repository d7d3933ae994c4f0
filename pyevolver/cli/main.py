"""Command-line interface that behaves like ``evolver``.

``pyevolver FILE.fe`` loads the datafile (running its ``read`` section) and
then reads commands from the terminal (prompt ``Enter command: ``) or from
standard input when it is not a terminal; ``-f FILE`` runs a command file
after loading.  ``pyevolver convert|show|sweep|study ...`` are the subcommands
of :mod:`pyevolver.cli.tools`.  Errors become messages and exit codes here only.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from .. import __version__, threads
from ..commands import interpreter as I
from ..commands.variables import READ_ONLY
from ..errors import InternalError, PyEvolverError
from ..session import deadline
from ..session.core import Session
from .tools import SUBCOMMANDS, main as tool_main

PROMPT = "Enter command: "
MORE = "more> "


def build_parser():
    p = argparse.ArgumentParser(
        prog="pyevolver",
        description="Surface Evolver datafiles and command scripts in Python.",
        epilog="Other commands: pyevolver convert IN OUT | pyevolver show FILE.fe -o "
               "shape.png | pyevolver sweep SPEC.toml | pyevolver study phase  (each with --help)")
    p.add_argument("datafile", help="Surface Evolver datafile (.fe)")
    p.add_argument("-f", dest="command_file", help="command file to run after loading")
    p.add_argument("-p", dest="threads", type=int, default=1,
                   help="accepted for compatibility with evolver (ignored)")
    p.add_argument("--timeout", type=_seconds, default=None, metavar="SECONDS",
                   help="stop any single command that runs longer than this (the "
                        "surface is left as it was before it); for unattended runs")
    p.add_argument("--version", action="version", version=f"pyevolver {__version__}")
    return p


def _seconds(text):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") \
            from None
    if not v > 0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text!r}")
    return v


def _find_datafile(name):
    if os.path.isfile(name):
        return name
    if not name.endswith(".fe") and os.path.isfile(name + ".fe"):
        return name + ".fe"
    return None


# exit status after Ctrl-C (SIGINT) in batch mode, as a shell reports a
# process ended by SIGINT (and by SIGTERM)
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143


def main(argv=None):
    try:
        return _main(argv)
    except I.Quit as q:                 # `q` in the datafile's read section or a script
        _flush_quietly()
        return q.code
    except BrokenPipeError:
        # the reader of our output went away (e.g. `| head`): exit quietly
        try:
            sys.stdout = open(os.devnull, "w")
        except OSError:
            pass
        return 0
    except (KeyboardInterrupt, I.Interrupted):
        # Ctrl-C outside a command (loading, reading input) or in batch mode:
        # files are written atomically, so nothing is left half-written
        _flush_quietly()
        if deadline.terminated["hit"]:
            sys.stderr.write("\nTerminated.\n")
            return EXIT_TERMINATED
        sys.stderr.write("\nInterrupted.\n")
        return EXIT_INTERRUPTED


def _flush_quietly():
    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        pass


def _main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in SUBCOMMANDS:        # a datafile named so: ./show
        return tool_main(argv)
    args = build_parser().parse_args(argv)
    np.seterr(all="ignore")        # overflows are reported as Evolver warnings, not numpy's
    deadline.handle_sigterm()      # SIGTERM: as Ctrl-C (the command undone, exit 143)
    threads.process_wide()         # BLAS limited for the whole run (pyevolver.threads)
    path = _find_datafile(args.datafile)
    if path is None:
        sys.stderr.write(f"pyevolver: cannot open datafile '{args.datafile}': no such file\n")
        return 1
    try:
        session = Session(None, None)
        session.time_limit = args.timeout
        session.load_file(path)
    except PyEvolverError as exc:
        sys.stderr.write(f"{exc}\n")
        return 1
    except MemoryError:
        sys.stderr.write(f"{path}: out of memory while loading the datafile\n")
        return 1
    except deadline.Alarm:          # (the alarm passed in the last instant of loading)
        sys.stderr.write(f"{path}: {deadline.message(session, 'loading the datafile')}\n")
        return 1
    except (I.Quit, I.Interrupted, KeyboardInterrupt):
        raise
    except Exception as exc:            # a bug of pyevolver: a message, not a traceback
        sys.stderr.write(f"{InternalError.from_exception(exc, path)}\n")
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
            try:
                session.run(text, where=args.command_file, stop_on_error=False)
            except I.Interrupted as exc:
                if not _interactive():
                    raise
                sys.stdout.write(f"\n{exc}\n")
        return repl(session)
    except I.Quit as q:
        sys.stdout.flush()
        return q.code


def _interactive():
    try:
        return sys.stdin.isatty()
    except (AttributeError, ValueError):
        return False


def history_file():
    return os.environ.get("PYEVOLVER_HISTORY") or \
        os.path.join(os.path.expanduser("~"), ".pyevolver_history")


def repl(session, stdin=None):
    """Read commands until ``q`` or end of input; returns the exit code.

    At a terminal the line editor is prompt_toolkit (history kept across
    runs in ~/.pyevolver_history or $PYEVOLVER_HISTORY, Tab completion,
    ``more> `` for unfinished commands); piped input is read plainly so that
    batch output stays byte-compatible with the Evolver's.
    """
    if stdin is None and sys.stdin.isatty() and sys.stdout.isatty():
        try:
            return _repl_terminal(session)
        except ImportError:           # prompt_toolkit not installed: plain prompts
            pass
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
            if not interactive:
                raise               # batch mode: main() exits with status 130
            sys.stdout.write("\n")
            buf = ""
            continue
        if not line:
            if buf.strip():
                _run(session, buf, lineno, interactive)
            return 0
        lineno += 1
        buf += line
        if not I.needs_more(buf):
            try:
                _run(session, buf, lineno, interactive)
            finally:
                buf = ""


def _run(session, text, lineno, interactive=True):
    """Run one input command.  Ctrl-C stops it; at a terminal the prompt
    returns, in batch mode the interruption propagates (exit status 130)."""
    try:
        session.run(text, where="<stdin>", line=max(1, lineno - text.count("\n") + 1),
                    stop_on_error=False)
    except I.Interrupted as exc:
        if not interactive:
            raise
        sys.stdout.write(f"\n{exc}\n")
    except KeyboardInterrupt:
        if not interactive:
            raise
        sys.stdout.write("\nInterrupted.\n")
    sys.stdout.flush()


def _repl_terminal(session):
    from prompt_toolkit import PromptSession
    from prompt_toolkit.history import FileHistory

    try:
        history = FileHistory(history_file())
    except OSError:
        history = None
    ps = PromptSession(history=history, completer=_completer(session),
                       complete_while_typing=False)
    buf = ""
    lineno = 0
    while True:
        try:
            line = ps.prompt(MORE if buf else PROMPT)
        except KeyboardInterrupt:            # Ctrl-C at the prompt drops the line
            buf = ""
            continue
        except EOFError:
            return 0
        lineno += 1
        buf += line + "\n"
        if I.needs_more(buf):
            continue
        text, buf = buf, ""
        _run(session, text, lineno)


# words the completer offers besides the session's own names
KEYWORDS = sorted({
    "if", "then", "else", "while", "do", "for", "foreach", "where", "procedure",
    "function", "local", "define", "attribute", "return", "break", "continue", "print",
    "printf", "errprintf", "sprintf", "list", "set", "unset", "fix", "unfix", "refine",
    "delete", "edgeswap", "histogram", "loghistogram", "read", "abort", "quit", "recalc",
    "vertex", "vertices", "edge", "edges", "facet", "facets", "body", "bodies",
    "sum", "avg", "max", "min", "count", "hessian", "hessian_seek", "equiangulate", "bfgs",
    "newton",
    "show_vol", "optimize", "integer", "real", "string", "on", "off",
})
ATTRIBUTES = ["id", "oid", "original", "x", "y", "z", "length", "area", "volume", "target",
              "pressure", "volconst", "density", "tension", "color", "frontcolor",
              "backcolor", "fixed", "valence", "on_constraint", "on_boundary",
              "vertex_normal", "no_refine", "value", "modulus"]
ATTRIBUTES += ["sqcurve", "mean_curvature", "dihedral", "facet_normal", "edge_vector",
               "value_of_constraint", "hit_constraint", "volfixed", "v_force", "v_velocity",
               "v_oldx", "on_quantity", "on_method_instance", "tolerance", "opacity", "bare"]


def _completer(session):
    from prompt_toolkit.completion import Completer, Completion

    class EvolverCompleter(Completer):
        def get_completions(self, document, complete_event):
            word = document.get_word_before_cursor(WORD=False)
            if not word or not (word[0].isalpha() or word[0] == "_"):
                return
            w = word.lower()
            names = set(KEYWORDS) | set(ATTRIBUTES) | set(I.TOGGLES)
            names |= set(session.commands) | set(session.arrays)
            names |= {k for k, v in session.variables.items()}
            names |= set(session.settings)
            names |= READ_ONLY
            s = session.surface
            if s is not None:
                names |= set(s.quantities)
                names |= {name for (_, name) in s.extra}
            for name in sorted(n for n in names if n.startswith(w) and n != w):
                yield Completion(name, start_position=-len(word))

    return EvolverCompleter()


if __name__ == "__main__":   # pragma: no cover
    sys.exit(main())
