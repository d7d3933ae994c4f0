"""The Session: one surface, its variables and commands.

The REPL, the CLI and the Python API share this object::

    from pyevolver import Session
    s = Session.load("cube.fe")
    s.total_energy          # 6.0
    s.run("print total_area")
"""
from __future__ import annotations

import sys
import time
from typing import Any, Callable, TextIO

import numpy as np

from . import deadline, health, popping, undo
from .deadline import deferred_sigint as _deferred_sigint
from .api import SessionAPI, progress_bar
from .result import GResult
from ..commands import constraints, element_attrs, elements, files, fresh, remesh, variables
from ..commands import interpreter as I
from ..commands.variables import DEFAULTS, READ_ONLY  # noqa: F401 (READ_ONLY: re-exported)
from ..constraints import (boundary_eval, boundary_groups, constrained_vertices,
                           project_to_constraints, restore_state, state)
from ..datafile.preprocess import _TooLong as _MacroTooLong, expand_macros
from ..datafile.reader import read_datafile
from ..datafile.writer import DumpSettings, dump as write_dump
from ..errors import (CommandError, DatafileError, InternalError, PyEvolverError,
                      UnsupportedError)
from ..evolve.iterate import IterateSettings, Iterator, _Constraints, progress_line
from ..expr import nodes as N
from ..limits import MAX_EXPANDED_LINE
from ..threads import limited
from ..model.build import build_surface
from ..remesh.quadratic import from_listed
from ..remesh.string import split_edges

# motion options that change what g does; refused rather than ignored
UNSUPPORTED_MOTION = ()


class Session(SessionAPI):
    """A loaded surface with its variables, settings, toggles, history,
    undo and output streams.

    The commands themselves live in :mod:`pyevolver.commands` (one
    registry, :mod:`pyevolver.commands.registry`) and take the session as
    their argument; the methods here are the public Python API: :meth:`load`,
    :meth:`run`, :meth:`g`, :meth:`value`, :attr:`quantities`,
    :attr:`total_energy`, :meth:`refine`, :meth:`equiangulate`, and from
    :class:`~pyevolver.session.api.SessionAPI` ``export``, ``snapshot``,
    ``plot_history``.
    """

    def __init__(self, out: TextIO | None = None, err: TextIO | None = None) -> None:
        self.out = out or sys.stdout
        self.err = err or sys.stderr
        self.surface: Any = None               # pyevolver.model.surface.Surface
        self.totals: Any = None                # pyevolver.methods.totals.Totals
        self.variables: dict[str, Any] = {}
        self.commands: dict[str, Any] = {}     # name -> interpreter.Proc
        self.letters: dict[str, Any] = {}      # single letters redefined with :::=
        self.arrays: dict[str, Any] = {}       # array variables (define name real[n])
        self.array_types: dict[str, Any] = {}
        self.attr_types: dict[tuple, str] = {}  # (kind, name) -> 'integer' / 'real' / ...
        self.toggles: dict[str, Any] = {}
        self.settings = dict(DEFAULTS)
        self.filename = ""
        self.start_time = time.time()
        self.interp = I.Interpreter(self)
        self._iterator = None
        self.counts: dict[str, int] = {}       # equi_count, refine_count, ... (spec §9.7)
        self._rng = None       # `random`, `j` (SessionAPI.rng, made when first used)
        self.iteration_counter = 0
        self.total_time = 0.0
        # seconds one top-level command may run (None: no limit); a command
        # that runs longer stops with an error and leaves the surface as it was
        self.time_limit: float | None = None
        self.history: list[tuple] = []         # (iteration, energy, area) of each g step
        self.command_history: list = []       # (number, text) of `history`, `!!` (REF: last 100)
        self.command_count = 0
        # REF reports some counts once per command, summed, at its end
        # ("Fixed: N", "Unfixed: N" first, then "Edges refined: N", ...)
        self.pending = {"Fixed": 0, "Unfixed": 0}

    # -- loading ---------------------------------------------------------------
    @classmethod
    def load(cls, filename: str, out: TextIO | None = None, err: TextIO | None = None,
             run_read: bool = True, text: str | None = None,
             timeout: float | None = None) -> "Session":
        """A session on a datafile.

        Parameters
        ----------
        filename : str
            The ``.fe`` datafile.
        out, err : file-like, optional
            Where output and messages go (default: stdout, stderr).
        run_read : bool
            Run the datafile's ``read`` section.
        text : str, optional
            The file's contents, when not to be read from disk.
        timeout : float, optional
            Seconds the loading, and then each command, may run (``time_limit``).
        """
        s = cls(out, err)
        s.time_limit = timeout
        s.load_file(filename, run_read, text)
        return s

    def load_file(self, filename: str, run_read: bool = True,
                  text: str | None = None) -> "Session":
        """Load a datafile into this session (:meth:`load`; the time limit covers it all)."""
        try:
            with deadline.limit(self):
                scene = read_datafile(filename, text)
                surface = build_surface(scene)
                if "listed_midpoints" in surface.__dict__:     # QUADRATIC in the datafile
                    surface = from_listed(surface)
                return self._install(filename, scene, surface, run_read)
        except (deadline.Alarm, I.TimeLimitExceeded):
            raise I.TimeLimitExceeded(f"{filename}: " + deadline.message(
                self, "loading the datafile")) from None
        except health.NUMERICAL as exc:          # (a method's matrix of huge input)
            raise DatafileError(health.explain(exc, load=True), filename) from None

    def _install(self, filename, scene, surface, run_read):
        self.filename = filename
        self.surface = surface
        for msg, line, col in scene.warnings:  # lines the Evolver warns about
            where = f"{filename}:{line}:{col}" if col else f"{filename}:{line}"
            self.write_err(f"{where}: warning: {msg}\n")
        files.warn_bare_edges(self, filename, scene, surface)
        constraints.record_order(self, scene, surface)     # constraints in datafile order
        self.on_assign_call = dict(scene.on_assign)
        if scene.constraint_names:             # named constraints and boundaries
            surface.constraint_names = dict(scene.constraint_names)
        if scene.boundary_names:
            surface.boundary_names = dict(scene.boundary_names)
        if scene.values.get("_period_exprs") is not None and surface.periods is not None:
            surface.period_exprs = scene.values["_period_exprs"]
        # OPTIMIZING_PARAMETERs: moved by g (pyevolver.evolve.optparams)
        surface.optimizing = dict(scene.optimizing)
        surface.param_deltas = dict(scene.param_deltas)
        self._iterator = None                  # no CG history, pressures not yet valid
        # REF's gravity flag (reported by G): on when the datafile declares a
        # nonzero gravity_constant or a body has a density (mound.fe: on with
        # gravity_constant 0; cube.fe: off with the default constant 1)
        b = surface.bodies
        self.toggles["gravity"] = int(scene.values.get("gravity_constant", 0) != 0 or
                                      bool(b.n and np.any(b.density)))
        self.variables = surface.params        # parameters and variables share one namespace
        files.scene_settings(self, scene)
        for flag in ("area_normalization", "autopop", "conj_grad", "torus_filled",
                     "effective_area", "normal_curvature", "approximate_curvature",
                     "runge_kutta", "jiggle"):
            if flag in scene.flags:             # top-section toggles (100grain.fe)
                self.toggles[flag] = 1
        if scene.values.get("autochop"):
            self.toggles["autochop"] = 1
            self.settings["autochop_length"] = float(scene.values["autochop"])
        self.commands = {}
        self.letters = {}
        self.arrays = {}
        self.macros = dict(scene.macros)       # keep_macros: expanded in commands
        files.init_view_matrix(self)
        for name, (typ, arr) in scene.arrays.items():     # a dump's global arrays
            self.arrays[name] = arr.copy()
            self.array_types[name] = typ
        for key, (typ, _size, _dims) in scene.attributes.items():   # define ... attribute
            self.attr_types[key] = typ
        try:
            self.recalc()
        except DatafileError:
            raise
        except PyEvolverError as exc:
            # the first evaluation failed (a method refused here...): at its declaration if known
            line = getattr(exc, "line", None)
            metric = getattr(self.surface, "metric", None)
            if line is None and metric is not None:     # e.g. a log of a negative in it
                line = metric.line
            lines = scene.source_lines
            raise DatafileError(str(exc), filename, line, None,
                                lines[line - 1] if line and lines and line <= len(lines)
                                else None) from None
        health.check_loaded(self, scene)       # overflowed coordinates, zero-area facets
        fresh.mark(self)                       # (a first r, u or V needs no new evaluation)
        for text, line in scene.top_commands:  # top-section procedures and functions
            self.run(text, where=filename, line=line, stop_on_error=False)
        for wline, msg in scene.read_warnings:
            self.err.write(f"{filename}:{wline}: {msg}\n")
        if run_read and scene.read_text:
            # an error abandons the rest of the read section (as in the
            # Evolver); the surface stays loaded.  A command refused by name
            # (a feature pyevolver lacks, which the Evolver would run) is
            # reported and the section goes on.
            for chunk, ln in I.split_commands(scene.read_text):
                try:
                    self.run_one(chunk, filename, scene.read_line + ln)
                except (I.Quit, I.Interrupted):
                    raise
                except PyEvolverError as exc:
                    self.write_err(f"{exc}\n")
                    if "not supported in pyevolver" not in str(exc):
                        break
        return self

    def dump(self, name: str | None = None) -> None:
        """``dump "file"``: write the surface as a datafile (no name: the
        datafile name with ``.dmp`` appended, as the Evolver does)."""
        if name is None:
            name = (self.filename or "pyevolver") + ".dmp"
        self.write(f"Dumping to {name}.\n")
        try:
            write_dump(self.surface, name,
                       settings=DumpSettings(self.filename, self.settings, self.toggles,
                                             self.attr_types))
        except OSError as exc:
            raise CommandError(f"dump: cannot write '{name}': {exc.strerror}") from None

    # -- output -----------------------------------------------------------------
    def note(self, text: str) -> None:
        """A message that ``quiet`` suppresses (REF: counts after r, v, toggle
        messages, mesh operation reports, the header of list)."""
        if not self.toggles.get("quiet"):
            self.write(text)

    def write(self, text: str) -> None:
        """Write to the output stream."""
        self.out.write(text)

    def write_err(self, text: str) -> None:
        """Write to the message stream (stderr)."""
        self.err.write(text)

    # -- running commands ----------------------------------------------------------
    def run(self, text: str, where: str = "<command>", line: int = 1,
            stop_on_error: bool = True, timeout: float | None = None) -> None:
        """Run command text (any number of commands).

        Each complete command is parsed then executed; a failing command
        leaves the surface and variables as they were.

        Parameters
        ----------
        text : str
            Commands of the Evolver's language, e.g. ``"r; u; g 10"``.
        where, line : str, int
            The location errors name.
        stop_on_error : bool
            Raise :class:`CommandError` at the first error (else print it
            and go on).
        timeout : float, optional
            Seconds each command may run (default: ``time_limit``).
        """
        with deadline.override(self, timeout):
            self._run(text, where, line, stop_on_error)

    def _run(self, text, where, line, stop_on_error):
        for chunk, ln in I.split_commands(text):
            try:
                self.run_one(chunk, where, line + ln - 1)
            except (I.Quit, I.Interrupted):
                raise
            except PyEvolverError as exc:
                if stop_on_error:
                    raise
                self.write_err(f"{exc}\n")

    def run_one(self, text: str, where: str = "<command>", line: int = 1) -> None:
        """Run one complete command; an error restores the state before it."""
        stripped = text.strip()
        if stripped.startswith("!") and not stripped.startswith("!="):
            # !!, !n, !prefix: a command from the history, echoed (manual)
            try:
                old = self._from_history(stripped[1:].strip())
            except CommandError as exc:
                raise CommandError(f"{where}:{line}: {exc}") from None
            self.write(old + "\n\n")
            return self.run_one(old, where, line)
        if getattr(self, "macros", None):
            try:
                text = expand_macros(text, self.macros)
            except _MacroTooLong:
                raise CommandError(f"{where}:{line}: #define macros expand this command "
                                   f"beyond {MAX_EXPANDED_LINE} characters") from None
        ast = I.parse_command(text, where, line)
        self._remember(stripped)
        snap, checked = self._snapshot(), False
        scopes = self.interp.env.scopes
        depth = len(scopes)
        scopes.append({})
        interp = self.interp
        outer = interp.deadline is None         # commands run by `read` share the limit
        if outer and self.time_limit:
            interp.deadline = time.monotonic() + self.time_limit
        try:
            with deadline.alarm(self.time_limit if outer else None):
                interp.execute(ast)
            health.check(self, snap[15], snap[-1][6])   # refresh; non-finite fails
            checked = True
        except (I.Quit, I.Interrupted):
            self.refresh()
            raise
        except KeyboardInterrupt:
            self._restore(snap)
            self.refresh()
            raise I.Interrupted("Interrupted: the surface is as it was before the command.") \
                from None
        except deadline.Alarm:
            self._restore(snap)
            raise I.TimeLimitExceeded(f"{where}:{line}: {deadline.message(self)}") from None
        except (I._Break, I._Continue, I._Return, I.Loaded):
            pass
        except PyEvolverError as exc:
            self._restore(snap)
            if isinstance(exc, CommandError) and str(exc).startswith(where):
                raise
            raise CommandError(f"{where}:{line}: {exc}") from None
        except RecursionError:
            self._restore(snap)
            raise CommandError(f"{where}:{line}: recursion too deep") from None
        except MemoryError:
            self._restore(snap)
            raise CommandError(f"{where}:{line}: out of memory; the command was "
                               f"abandoned") from None
        except health.NUMERICAL as exc:
            self._restore(snap)             # numerical failures in plain words
            raise CommandError(f"{where}:{line}: {health.explain(exc)}") from None
        except Exception as exc:
            # a bug of pyevolver, not of the script: the session goes on, the
            # surface as it was (PYEVOLVER_TRACEBACK=1 prints the traceback)
            self._restore(snap)
            raise InternalError.from_exception(exc, f"{where}:{line}") from None
        finally:
            del scopes[depth:]
            if outer:
                interp.deadline = None
            counts, self.pending = self.pending, {"Fixed": 0, "Unfixed": 0}
        for word, n in counts.items():
            if n and word in ("Fixed", "Unfixed"):
                self.note(f"{word}: {n}\n")
            elif n:
                self.write(f"{word}: {n}\n")
        if not checked:
            self.refresh()

    HISTORY_SIZE = 100

    def _remember(self, text):
        """Successfully parsed commands go into the history list (the last
        100, numbered from 1), as in REF."""
        self.command_count = self.command_count + 1
        h = self.command_history
        h.append((self.command_count, text))
        self.command_history = h[-self.HISTORY_SIZE:]

    def _from_history(self, key):
        h = self.command_history
        if key == "!":
            if h:
                return h[-1][1]
        elif key.isdigit():
            for num, text in h:
                if num == int(key):
                    return text
            raise CommandError("Command not in history list.")      # REF's ERROR 1587
        else:
            for num, text in reversed(h):
                if text.startswith(key):
                    return text
        raise CommandError("Command not found in history.")          # REF's ERROR 1588

    def show_history(self) -> None:
        """``history``: the saved commands, ``n) text``."""
        for num, text in self.command_history:
            self.write(f"{num}) {text}\n")

    def report(self, word: str, n: int) -> None:
        """Add ``n`` to the count REF prints as ``word: total`` when the
        current command ends."""
        self.pending[word] = self.pending.get(word, 0) + n

    def _snapshot(self):
        """The state a failing command returns to (:func:`pyevolver.session.undo.snapshot`)."""
        return undo.snapshot(self)

    def _iterator_state(self):
        it = self._iterator
        return it and (it.cg_history, it.cg_S_old, it.cg_f_old, it.pressures_valid)

    def _restore(self, snap):
        undo.restore(self, snap)        # (back to a _snapshot)

    # -- evaluation ------------------------------------------------------------------
    def recalc(self, keep_cg: bool = False, reposition: bool = False,
               totals: Any = None) -> None:
        """Recompute energies, areas and volumes (and reset the CG history,
        as the Evolver's recalc does, unless ``keep_cg``).

        ``totals``: an evaluation of the current coordinates a solver has
        just made; taken as it is unless the session's settings change how
        the surface is evaluated (gravity, curvature mode, periods).

        ``reposition`` (the ``recalc`` command): first put the vertices on
        parametric boundaries where their parameters now say (cat.fe's
        ``rmax := 1; recalc``: REF's energy 14.5547875690274) and project
        the vertices on level-set constraints onto them (sphere.fe's
        ``rad := 1.2; recalc``), as evolver-nox-d does after a parameter
        changed."""
        s = self.surface
        self._stale_totals = None              # (autopop: pyevolver.session.popping)
        if s is None:
            return
        if reposition:
            groups = boundary_groups(s) if s.boundaries else []
            if groups or s.vcon:
                s.X = s.X.copy()
                for bid, rows in groups:
                    s.X[rows], _ = boundary_eval(s, bid, s.vattr["params"][rows])
                on = constrained_vertices(s)
                if on.any():
                    project_to_constraints(s, np.nonzero(on)[0])
                s.__dict__.pop("_lift_cache", None)
        before = (s.periods, s.gravity_constant, getattr(s, "gravity_on", None),
                  getattr(s, "curvature_mode", None))
        if getattr(s, "period_exprs", None) is not None:
            self._eval_periods(s)
        s.gravity_constant = self.variables.get("gravity_constant", s.gravity_constant)
        s.gravity_on = bool(self.toggles.get("gravity", 1))
        s.curvature_mode = ("norm" if self.toggles.get("normal_curvature") else
                            "eff" if self.toggles.get("effective_area") else "plain")
        after = (s.periods, s.gravity_constant, s.gravity_on, s.curvature_mode)
        if (totals is None or totals.surface is not s or after[0] is not before[0]
                or after[1:] != before[1:]):
            t = s.evaluate()
        else:
            t = totals
        s.bodies.volume = t.volumes
        self.totals = t
        if not keep_cg:
            self.reset_cg()

    def _eval_periods(self, s):
        """PERIODS given by expressions: re-evaluated at each recalc (manual:
        "give a recalc command whenever you change such a variable")."""
        env = N.MapEnv(self.variables)
        vals = [float(e) if isinstance(e, float) else float(e.ev(env)) for e in s.period_exprs]
        sd = s.sdim
        P = np.array(vals).reshape(sd, sd)
        if not np.all(np.isfinite(P)):
            raise CommandError("PERIODS: the values must be finite")
        if not np.array_equal(P, s.periods[:sd, :sd]):
            s.periods = s.periods.copy()
            s.periods[:sd, :sd] = P
            s.__dict__.pop("_lift_cache", None)

    # -- evolution -------------------------------------------------------------------
    @property
    def iterator(self):
        """The :class:`~pyevolver.evolve.iterate.Iterator` of the session's
        surface (created on first use), its settings those of the session."""
        if self._iterator is None:
            self._iterator = Iterator(lambda: self.surface)
        self._iterator.rng = self.rng           # jiggle: the generator of `j` and `random`
        self._iterator.settings = IterateSettings.from_mappings(self.settings, self.toggles)
        return self._iterator

    def reset_cg(self) -> None:
        """Forget the conjugate-gradient history."""
        if self._iterator is not None:
            self._iterator.cg_history = None

    def g(self, n: int = 1, callback: Callable[[Any], Any] | None = None, echo: bool = False,
          progress: Any = None) -> GResult:
        """Run ``n`` iteration steps; returns a :class:`~.result.GResult`: the
        list of step results with the final energy, area, scale and pressures.

        ``callback(result)`` is called after each step; returning True stops
        the run.  With ``echo`` the Evolver's progress lines are printed.
        ``progress``: a tqdm bar (True, False, or None for long runs at a
        terminal or in a notebook; never with ``echo``).
        """
        popping.check_supported(self)
        if self.toggles.get("_effective_area_motion"):
            # REF's effective_area command also changes the motion (the top-section
            # keyword EFFECTIVE_AREA changes only the squared curvature)
            raise UnsupportedError("g with effective_area on", "the effective-area motion "
                                   "is not implemented")
        results = GResult()
        if self.surface.nv == 0:                # e.g. after `t` removed everything (REF)
            self.write("WARNING 1051: No vertices. Did you forget to load a surface?\n\n")
            return results.finish(self)
        bar = None if echo else progress_bar(n, progress, "g")
        try:
            with limited():                     # (once for all the steps: pyevolver.threads)
                self._steps(n, callback, echo, results, bar)
        finally:
            if bar is not None:
                bar.close()
        return results.finish(self)

    def _steps(self, n, callback, echo, results, bar):
        start = it = None
        for k in range(n, 0, -1):
            self.interp.tick()
            it = self.iterator if start is None or it is None else it   # (else: the scale alone
            it.settings.scale = self.settings["scale"]                   # is new in a g n run)
            r = it.step(start=start)
            # what the step did, kept by the session: the motion (v_force, v_oldx, v_velocity),
            # the optimized scale, the totals, the iteration count and the time
            self._last_motion = r.motion
            if r.printed and not it.settings.fixed_scale:
                self.settings["scale"] = r.scale
            self.recalc(keep_cg=True, totals=r.totals)
            if r.printed:
                self.iteration_counter += 1
                self.total_time += r.scale
                r.energy, r.area = self.totals.energy, self.totals.total_area
            if results:                 # only the last step keeps its arrays (memory)
                results[-1].totals = results[-1].motion = None
            results.append(r)
            self.history.append((self.iteration_counter, r.energy, r.area))
            if bar is not None:
                bar.update(1)
                bar.set_postfix(energy=f"{r.energy:.10g}", refresh=False)
            popping.after_move(self, r)        # autopop, autochop
            if echo:
                off = self.__dict__.get("suppressed_warnings") or ()
                for w in r.warnings:
                    if any(w.startswith(f"WARNING {n}:") for n in off) or \
                            ("Total difference" in w and 1055 in off):
                        continue                    # suppress_warning n
                    if w.startswith(("WARNING 1055", "Total difference", "WARNING 1864")):
                        # REF writes these to stderr, the pair (and 1864) followed by a
                        # blank line
                        self.write_err(w + ("\n" if w.startswith("WARNING 1055") else "\n\n"))
                    else:
                        self.write(w + "\n")
                if r.printed and not self.toggles.get("quiet") and not self.toggles.get("quietgo"):
                    self.write(progress_line(k, r, self.surface.string) + "\n")
            if r.message == "increase":
                break
            if callback is not None and callback(r):
                break
            # the next step starts from this evaluation when nothing changed it
            # (no autopop or autochop; a callback of the API may change anything)
            chain = (self.totals is r.totals and getattr(callback, "pure", callback is None)
                     and not self.toggles.get("autopop") and not self.toggles.get("autochop"))
            start = r.totals if chain else None

    def go(self, n: int) -> None:
        """``g n`` at the prompt: steps with progress lines.

        Ctrl-C (SIGINT) during the run is deferred to the end of the current
        step: the step completes, the run stops and the surface is the one
        after that step."""
        with _deferred_sigint() as flag:
            def stop(r):
                return flag["hit"]
            setattr(stop, "pure", True)     # (changes nothing: steps may chain their evaluations)
            self.g(n, echo=True, callback=stop)
        if flag["hit"]:
            # the rest of the command (an enclosing loop too) is abandoned; the
            # surface is the one after the last complete iteration
            raise I.Interrupted("Interrupted: stopped after a complete iteration.")

    def bfgs(self, n: int, echo: bool = True, callback: Callable[[Any], Any] | None = None,
             progress: Any = None) -> Any:
        """``bfgs n``: at most ``n`` iterations of BFGS with a weak Wolfe line
        search (:mod:`pyevolver.evolve.bfgs`; Lewis & Overton 2013), the
        minimizer for nonsmooth energies such as ``circle_willmore``.  Free
        surfaces only: fixed vertices stay, but bodies with fixed volumes,
        FIXED quantities, level-set constraints and boundaries are refused.
        Prints ``k. area: .. energy: ..`` per iteration (counting down, as
        ``g``) and returns the :class:`~pyevolver.evolve.bfgs.BFGSResult`;
        ``callback(result)`` may stop the run, and so does Ctrl-C (at the end
        of the current iteration, the surface that of the last one).
        ``progress``: a tqdm bar, as for :meth:`g` (never with ``echo``)."""
        self.no_string("bfgs")
        s = self.surface
        if s is None or s.nv == 0:
            raise CommandError("bfgs: no surface loaded")
        from ..evolve.bfgs import check_free, minimize_surface   # (imported when first used)
        check_free(s)
        X0 = state(s)

        with _deferred_sigint() as flag:
            def cb(r):
                self.interp.tick()
                if echo and not self.toggles.get("quiet"):
                    self.write("%3d. area: %#17.15g energy: %#17.15g  scale: %#g\n"
                               % (n - r.nit, r.area, r.energy, r.step))
                if bar is not None:
                    bar.update(1)
                return flag["hit"] or (callback is not None and callback(r))
            bar = None if echo else progress_bar(int(n), progress, "bfgs")
            try:
                r = minimize_surface(s, int(n), callback=cb)
            except Exception:
                restore_state(s, X0)
                self.recalc()
                raise
            finally:
                if bar is not None:
                    bar.close()
        if echo and r.nit == 0:
            self.write(f"bfgs: no step taken ({r.message}).\n")
        self.recalc()
        return r

    def newton(self, n: int, echo: bool = True,
               callback: Callable[[Any], Any] | None = None) -> Any:
        """``newton n``: at most ``n`` damped Newton (Levenberg–Marquardt)
        steps with the exact Hessian on all free coordinates
        (:mod:`pyevolver.evolve.newton`); fixed volumes, FIXED quantities
        and level-set constraints are honoured as in ``hessian``.  Prints
        ``k. area: .. energy: ..  delta: ..`` per step (counting down, as
        ``g``) and returns the :class:`~pyevolver.evolve.newton.NewtonResult`;
        ``callback(result)`` may stop the run, and so does Ctrl-C (after the
        current step)."""
        self.no_string("newton")
        s = self.surface
        if s is None or s.nv == 0:
            raise CommandError("newton: no surface loaded")
        with _deferred_sigint() as flag:
            def cb(r):
                self.recalc(totals=r.totals)
                self.interp.tick()
                if echo and not self.toggles.get("quiet"):
                    self.write("%3d. area: %#17.15g energy: %#17.15g  delta: %#g\n"
                               % (n - r.nit, self.totals.total_area, r.energy, r.delta))
                return flag["hit"] or (callback is not None and callback(r))
            X0 = state(s)
            from ..evolve.newton import damped_newton
            try:
                r = damped_newton(self.iterator, n, callback=cb)
            except Exception:
                restore_state(self.surface, X0)
                self.recalc()
                raise
        if echo and r.nit == 0:
            self.write(f"newton: no step taken ({r.message}).\n")
        self.recalc()
        return r

    def hessian(self, seek: bool = False, max_scale: float | None = None,
                echo: bool = True) -> Any:
        """``hessian``: one Newton step on the constrained problem;
        ``hessian_seek [max]``: a line search along the Newton direction
        (scale at most ``max``, default 1).  Returns a :class:`StepResult`
        (:func:`pyevolver.evolve.newton.hessian_step`)."""
        if self.surface is None or self.surface.nv == 0:
            # (everything deleted; REF: "No vertices" warnings or unrelated errors)
            raise CommandError(f"{'hessian_seek' if seek else 'hessian'}: the surface has "
                               f"no vertices")
        it = self.iterator
        if not it.pressures_valid and len(_Constraints(self.surface)):
            raise CommandError("Pressures invalid. Do regular iteration before Hessian "
                               "to set pressures.")
        from ..evolve.eigen import beyond_reference   # (the Hessian's modules: when first used)
        from ..evolve.newton import hessian_step
        seen = self.__dict__.setdefault("_beyond_noted", set())
        for note in beyond_reference(self.surface) if echo else ():
            if note not in seen:            # where REF refuses (once per session)
                seen.add(note)
                self.write_err(note + "\n")
        r = hessian_step(it, seek, max_scale, normal=it.settings.hessian_normal,
                         eps=float(self.settings.get("hessian_epsilon", 1e-10)))
        self.recalc(totals=r.totals)
        if r.message == "infinite":
            raise CommandError("hessian: the Newton step gives a non-finite energy; "
                               "the surface is unchanged")
        r.energy, r.area = self.totals.energy, self.totals.total_area
        if echo:
            for w in r.warnings:
                if w.startswith(("WARNING 1825", "WARNING 1596")):
                    self.write_err(w + "\n")          # REF: to stderr, then a blank line
                else:
                    self.write(w + "\n")
            if not self.toggles.get("quiet"):
                # hessian_seek adds its scale, as REF does
                tail = "  scale: %#g" % r.scale if seek else ""
                self.write("%3d. %s: %#17.15g energy: %#17.15g%s\n"
                           % (1, "length" if self.surface.string else "area", r.area,
                              r.energy, tail))
        return r

    # -- mesh upkeep ------------------------------------------------------------------
    def _replace_surface(self, new):
        self.surface = new
        self.recalc()
        fresh.mark(self)

    def no_string(self, what: str, surface: Any = None) -> None:
        """Refuse ``what`` by name on a string-model surface."""
        s = self.surface if surface is None else surface
        if s is not None and s.string:
            raise UnsupportedError(f"{what} in the string model")

    def _string_split(self, edges):
        self._replace_surface(split_edges(self.surface, edges))
        return len(edges)

    def refresh(self) -> None:
        """Recompute the energies after a command (unless ``autorecalc`` is off)."""
        if self.toggles.get("autorecalc", 1):
            stale = self.__dict__.get("_stale_totals")
            self.recalc(keep_cg=True)
            popping.keep_stale(self, stale)
            fresh.mark(self)

    # -- the public API: values ----------------------------------------------------
    @property
    def total_energy(self) -> float:
        """The total energy at the current coordinates."""
        return self.totals.energy

    @property
    def total_area(self) -> float:
        """The total area (string model: length) at the current coordinates."""
        return self.totals.total_area

    @property
    def quantities(self) -> dict:
        """``{name: value}`` of the named quantities and method instances at
        the current coordinates (as ``v`` and ``name.value`` report them)."""
        if self.totals is None:
            return {}
        return {k: float(v) for k, v in self.totals.quantity_values.items()}

    def value(self, expr: str) -> float | str:
        """The value of one expression of the command language.

        Parameters
        ----------
        expr : str
            E.g. ``"total_energy"``, ``"body[1].volume"``, ``"max(vertex, z)"``.

        Returns
        -------
        float or str
        """
        ast = I.parse_command(f"print {expr}", "<value>")
        stmts = ast[1] if ast[0] == "seq" else [ast]
        if len(stmts) != 1 or stmts[0][0] != "print":
            raise CommandError(f"value: '{expr}' is not one expression")
        v = self.interp.value(stmts[0][1])
        return v if isinstance(v, str) else float(v)

    def count(self, kind: str) -> int:
        """The number of ``kind`` elements (``"vertex"``, ``"edge"``,
        ``"facet"``, ``"body"``)."""
        return elements.count(self, kind)

    def internal(self, name: str) -> Any:
        """The value of a built-in name (``vertex_count``, a setting, a toggle)."""
        return variables.internal(self, name)

    def get_attr(self, base: Any, name: str, idx: Any = None) -> Any:
        """``base.name[idx]`` of an element or quantity reference
        (:func:`pyevolver.commands.element_attrs.get_attr`)."""
        return element_attrs.get_attr(self, base, name, idx)

    def set_attr(self, base: Any, name: str, idx: Any, value: Any) -> None:
        """``base.name[idx] := value`` (:func:`pyevolver.commands.element_attrs.set_attr`)."""
        element_attrs.set_attr(self, base, name, idx, value)

    def set_variable(self, name: str, value: Any) -> None:
        """``name := value`` (settings, parameters and user variables)."""
        variables.set_variable(self, name, value)

    # -- the public API: mesh operations (as the commands r, u, edgeswap) ------------
    def refine(self, echo: bool = True) -> None:
        """``r``: refine every edge and facet (:func:`pyevolver.commands.remesh.refine`)."""
        remesh.refine(self, echo)

    def equiangulate(self, echo: bool = True) -> int:
        """``u``: one equiangulation sweep; returns the number of flips."""
        return remesh.equiangulate(self, echo)

    def edgeswap(self, edges: Any, echo: bool = True) -> int:
        """``edgeswap``: flip the given edges (0-based indices, shape (k,));
        returns the number flipped."""
        return remesh.edgeswap(self, edges, echo)

    def replace_load(self, name: str) -> None:
        """``replace_load "file"`` (:func:`pyevolver.commands.files.replace_load`)."""
        files.replace_load(self, name)

    def __repr__(self) -> str:
        s = self.surface
        if s is None:
            return "<Session: no surface>"
        energy = f"{self.totals.energy:.10g}" if self.totals is not None else "?"
        return (f"<Session {self.filename or '(no file)'}: {s.nv} vertices, {s.ne} edges, "
                f"{s.n_facets} facets, {s.bodies.n} {'body' if s.bodies.n == 1 else 'bodies'}; "
                f"energy {energy}>")
