"""The Session: one surface, its variables and commands.

The REPL, the CLI and the Python API share this object::

    from pyevolver import Session
    s = Session.load("cube.fe")
    s.total_energy          # 6.0
    s.run("print total_area")
"""
from __future__ import annotations

import contextlib
import copy
import math
import sys
import time

import numpy as np

from .api import SessionAPI, progress_bar
from ..commands import interpreter as I
from ..datafile.writer import DumpSettings, dump as write_dump
from ..datafile.preprocess import _TooLong as _MacroTooLong, expand_macros
from ..datafile.reader import read_datafile
from ..errors import (CommandError, DatafileError, ExpressionError, InternalError,
                     PyEvolverError, UnsupportedError)
from ..evolve.bfgs import check_free, minimize_surface
from ..evolve.iterate import IterateSettings, Iterator, _Constraints, progress_line
from ..evolve.newton import damped_newton, hessian_step
from ..expr import nodes as N
from ..limits import MAX_EXPANDED_LINE, MAX_NESTING
from ..constraints import (boundary_eval, boundary_groups, constrained_vertices,
                           project_to_constraints, restore_state, state)
from ..model.build import build_surface
from ..remesh.edge_divide import edge_divide, long_edges

READ_ONLY = {
    "total_energy", "total_area", "total_length", "vertex_count", "edge_count",
    "facet_count", "body_count", "facetedge_count", "space_dimension",
    "surface_dimension", "torus", "datafilename", "equi_count", "edge_delete_count",
    "vertex_pop_count", "edge_pop_count", "notch_count", "refine_count", "where_count",
    "iteration_counter", "total_time", "random", "quantity_count", "symmetry_group",
    "simplex_representation", "lagrange_order", "date_and_time", "linear", "quadratic",
    "clock",
}
DEFAULTS = {
    "scale": 0.1, "scale_limit": 1.0, "scale_scale": 1.0, "target_tolerance": 1e-4,
    "constraint_tolerance": 1e-12, "jiggle_temperature": 0.05, "random_seed": 1.0,
    "autochop_length": 0.0, "integral_order_1d": 3.0, "integral_order_2d": 6.0,
    "hessian_epsilon": 1e-8, "sq_mean_mix": 0.0,
}



@contextlib.contextmanager
def _deferred_sigint():
    """Ctrl-C (SIGINT) only sets ``flag["hit"]`` while the block runs (so a
    ``g`` or ``bfgs`` run can stop at the end of a complete iteration); the
    previous handler is restored after.  Outside the main thread, a no-op."""
    import signal
    import threading
    flag = {"hit": False}
    old = None
    if threading.current_thread() is threading.main_thread():
        def handler(signum, frame):
            flag["hit"] = True
        try:
            old = signal.signal(signal.SIGINT, handler)
        except (ValueError, OSError):
            old = None
    try:
        yield flag
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)

# motion options that change what g does; refused rather than ignored
UNSUPPORTED_MOTION = ("area_normalization", "normal_motion", "runge_kutta",
                      "approximate_curvature", "diffusion", "autopop", "jiggle")


class Session(SessionAPI):
    """A loaded surface with its variables, commands and output streams
    (the Python API's extras: :class:`pyevolver.session.api.SessionAPI`)."""

    def __init__(self, out=None, err=None):
        self.out = out or sys.stdout
        self.err = err or sys.stderr
        self.surface = None
        self.totals = None
        self.variables = {}
        self.commands = {}                     # name -> interpreter.Proc
        self.letters = {}                      # single letters redefined with :::=
        self.arrays = {}                       # array variables (define name real[n])
        self.array_types = {}
        self.attr_types = {}                   # (kind, name) -> 'integer' / 'real' / ...
        self.toggles = {}
        self.settings = dict(DEFAULTS)
        self.filename = ""
        self.start_time = time.time()
        self.interp = I.Interpreter(self)
        self._iterator = None
        self.counts = {}                       # equi_count, refine_count, ... (spec §9.7)
        self.rng = np.random.default_rng(1)    # `random`, `j`; reseeded by random_seed :=
        self.iteration_counter = 0
        self.total_time = 0.0
        # seconds one top-level command may run (None: no limit); a command
        # that runs longer stops with an error and leaves the surface as it was
        self.time_limit = None
        self.history = []                      # (iteration, energy, area) of each g step
        self.command_history = []              # (number, text) of `history`, `!!` (REF: last 100)
        self.command_count = 0
        # REF reports some counts once per command, summed, at its end
        # ("Fixed: N", "Unfixed: N" first, then "Edges refined: N", ...)
        self.pending = {"Fixed": 0, "Unfixed": 0}

    # -- loading ---------------------------------------------------------------
    @classmethod
    def load(cls, filename, out=None, err=None, run_read=True, text=None):
        """A session on the datafile ``filename`` (``text``: its contents,
        when not to be read from disk)."""
        s = cls(out, err)
        s.load_file(filename, run_read, text)
        return s

    def load_file(self, filename, run_read=True, text=None):
        scene = read_datafile(filename, text)
        surface = build_surface(scene)
        return self._install(filename, scene, surface, run_read)

    def _install(self, filename, scene, surface, run_read):
        self.filename = filename
        self.surface = surface
        for msg, line, col in scene.warnings:  # lines the Evolver warns about
            where = f"{filename}:{line}:{col}" if col else f"{filename}:{line}"
            self.write_err(f"{where}: warning: {msg}\n")
        self._warn_bare_edges(filename, scene, surface)
        self._record_order(scene, surface)     # constraints in datafile order
        self.on_assign_call = dict(scene.on_assign)
        if scene.constraint_names:             # named constraints and boundaries
            surface.constraint_names = dict(scene.constraint_names)
        if scene.boundary_names:
            surface.boundary_names = dict(scene.boundary_names)
        if scene.values.get("_period_exprs") is not None and surface.periods is not None:
            surface.period_exprs = scene.values["_period_exprs"]
        self._iterator = None                  # no CG history, pressures not yet valid
        # REF's gravity flag (reported by G): on when the datafile declares a
        # nonzero gravity_constant or a body has a density (mound.fe: on with
        # gravity_constant 0; cube.fe: off with the default constant 1)
        b = surface.bodies
        self.toggles["gravity"] = int(scene.values.get("gravity_constant", 0) != 0 or
                                      bool(b.n and np.any(b.density)))
        self.variables = surface.params        # parameters and variables share one namespace
        self._scene_settings(scene)
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
        self._init_view_matrix()
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
            # the first evaluation failed (e.g. a method refused on this
            # surface): located at the quantity's declaration when known
            line = getattr(exc, "line", None)
            lines = scene.source_lines
            raise DatafileError(str(exc), filename, line, None,
                                lines[line - 1] if line and lines and line <= len(lines)
                                else None) from None
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

    def _warn_bare_edges(self, filename, scene, s):
        """REF warns at load about each edge of a soapfilm surface that is on
        no facet and not marked BARE ("Edge 19 has no facets, and is not
        marked "bare".")."""
        if s.string or not s.nf or not s.ne or len(scene.edges.ids) > s.ne:
            return
        FE = np.asarray(s.FE)
        used = np.zeros(s.ne, bool)
        used[np.where(FE >= 0, FE, ~FE).ravel()] = True
        blk = scene.edges
        for i in np.nonzero(~used[:len(blk.ids)])[0].tolist():
            attrs = blk.attrs.get(i, ())
            if any(kw == "bare" for kw, _ in attrs):
                continue
            self.write_err(f"{filename}:{blk.lines[i]}: warning: edge {blk.ids[i]} has no "
                           f"facets and is not marked bare\n")

    def _scene_settings(self, scene):
        for k in ("scale_limit", "constraint_tolerance"):
            if k in scene.values:
                self.settings[k] = scene.values[k]
        if "total_time" in scene.values:        # TOTAL_TIME: a dump goes on with its clock
            self.total_time = float(scene.values["total_time"])
        if "scale" in scene.values:
            self.settings["scale"] = scene.values["scale"]
            if scene.values.get("scale_fixed"):
                self.toggles["_fixed_scale"] = 1      # SCALE x FIXED: the m command

    # -- dump and load (commands) --------------------------------------------------
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

    def _read_new(self, cmd, name):
        import os
        if not os.path.isfile(name):
            if os.path.exists(name):
                raise CommandError(f"{cmd}: '{name}' is not a regular file (a directory, "
                                   f"device or pipe)")
            raise CommandError(f"{cmd}: cannot find datafile '{name}'")
        scene = read_datafile(name)
        return scene, build_surface(scene)

    def load_command(self, name):
        """``load "file"``: a fresh start on another datafile (variables,
        commands and toggles forgotten; its read section runs)."""
        scene, surface = self._read_new("load", name)
        out, err, limit = self.out, self.err, self.time_limit
        self.__init__(out, err)
        self.time_limit = limit
        self._install(name, scene, surface, True)

    def replace_load(self, name):
        """``replace_load "file"``: the surface of another datafile replaces
        the current one; variables, commands and toggles are kept, the new
        file's parameters and settings override, its read section is not run."""
        scene, surface = self._read_new("replace_load", name)
        old = self.surface
        if old is not None:
            for qname in old.quantities:
                if qname not in surface.quantities:
                    raise UnsupportedError(
                        f"replace_load: the quantity or method instance '{qname}' of the "
                        f"current surface is not declared in {name}",
                        "the Evolver would keep it for the new surface")
            for cid, c in old.constraints.items():
                if cid not in surface.constraints:
                    raise UnsupportedError(
                        f"replace_load: constraint {cid} of the current surface is not "
                        f"declared in {name}", "the Evolver would keep it")
        params = self.variables
        params.update(surface.params)
        surface.params = params
        self.surface = surface
        self.filename = name
        self._iterator = None
        self._scene_settings(scene)
        self.recalc()

    def addload(self, name):
        """``addload "file"``: the file's elements added to the surface,
        numbered after the existing ones; its declarations override, its
        read section is not run."""
        from ..remesh.merge import append_surface
        scene, new = self._read_new("addload", name)
        if self.surface is None:
            raise CommandError("addload: no surface is loaded")
        if new.string:
            self.no_string("addload", new)
        self.no_string("addload")
        merged = append_surface(copy.deepcopy(self.surface), new)
        self.variables.update(merged.params)
        merged.params = self.variables
        if "gravity_constant" in scene.values:
            merged.gravity_constant = scene.values["gravity_constant"]
        self.surface = merged
        self._iterator = None
        self.recalc()

    def _init_view_matrix(self):
        """The graphics view matrix (exporters read it): the Evolver's initial
        view fits the bounding box into [-1, 1]^3."""
        s = self.surface
        d = s.sdim
        M = np.eye(d + 1)
        if s.nv:
            lo, hi = s.X.min(axis=0), s.X.max(axis=0)
            size = float(np.max(hi - lo))
            if size > 0:
                sc = 2.0 / size
                for k in range(d):
                    M[k, k] = sc
                    M[k, d] = -sc * (lo[k] + hi[k]) / 2
        self.arrays["view_matrix"] = M
        self.array_types["view_matrix"] = "real"

    # -- output -----------------------------------------------------------------
    def note(self, text):
        """A message that ``quiet`` suppresses (REF: counts after r, v, toggle
        messages, mesh operation reports, the header of list)."""
        if not self.toggles.get("quiet"):
            self.write(text)

    def write(self, text):
        self.out.write(text)

    def write_err(self, text):
        self.err.write(text)

    # -- running commands ----------------------------------------------------------
    def run(self, text, where="<command>", line=1, stop_on_error=True):
        """Run command text (any number of commands).

        Each complete command is parsed then executed; a failing command
        leaves the surface and variables as they were, prints its error and
        (``stop_on_error``) raises :class:`CommandError`.
        """
        for chunk, ln in I.split_commands(text):
            try:
                self.run_one(chunk, where, line + ln - 1)
            except (I.Quit, I.Interrupted):
                raise
            except PyEvolverError as exc:
                if stop_on_error:
                    raise
                self.write_err(f"{exc}\n")

    def run_one(self, text, where="<command>", line=1):
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
        snap = self._snapshot()
        scopes = self.interp.env.scopes
        depth = len(scopes)
        scopes.append({})
        interp = self.interp
        outer = interp.deadline is None         # commands run by `read` share the limit
        if outer and self.time_limit:
            interp.deadline = time.monotonic() + self.time_limit
        try:
            interp.execute(ast)
            if self.surface is not None and not np.all(np.isfinite(self.surface.X)):
                # e.g. a huge jiggle or a boundary formula out of its domain
                raise CommandError("the command would make vertex coordinates infinite or "
                                   "NaN")
        except (I.Quit, I.Interrupted):
            self.refresh()
            raise
        except KeyboardInterrupt:
            self._restore(snap)
            self.refresh()
            raise I.Interrupted("Interrupted: the surface is as it was before the command.") \
                from None
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

    def show_history(self):
        """``history``: the saved commands, ``n) text``."""
        for num, text in self.command_history:
            self.write(f"{num}) {text}\n")

    def report(self, word, n):
        """Add ``n`` to the count REF prints as ``word: total`` when the
        current command ends."""
        self.pending[word] = self.pending.get(word, 0) + n

    def _snapshot(self):
        s = self.surface
        b = s.bodies if s is not None else None
        return (dict(self.variables), dict(self.commands), dict(self.letters),
                {k: v.copy() for k, v in self.arrays.items()}, dict(self.toggles),
                dict(self.settings),
                None if s is None else s.X.copy(),
                None if b is None or not b.n else (b.target.copy(), b.pressure.copy(),
                                                    b.volconst.copy(), b.density.copy(),
                                                    b.lagrange.copy()),
                None if s is None else {k: (q.target, q.modulus, q.kind, q.pressure,
                                            q.tolerance, list(q.methods))
                                        for k, q in s.quantities.items()},
                None if s is None else {k: v.copy() for k, v in s.extra.items()},
                None if s is None else {k: v.copy() for k, v in s.vattr.items()},
                None if s is None else {k: v.copy() for k, v in s.eattr.items()},
                None if s is None else {k: v.copy() for k, v in s.fattr.items()},
                None if s is None else {k: m.copy() for k, m in s.vcon.items()},
                s, self.totals, self._iterator_state(),
                None if s is None else ({k: m.copy() for k, m in s.econ.items()},
                                        {k: m.copy() for k, m in s.fcon.items()},
                                        s.gravity_constant, s.sq_curvature_modulus),
                self.filename,
                {k: dict(v) for k, v in self.__dict__.get("_attr_store", {}).items()})

    def _iterator_state(self):
        it = self._iterator
        if it is None:
            return None
        return (it.cg_history, it.cg_S_old, it.cg_f_old, it.pressures_valid)

    def _restore(self, snap):
        (vars_, cmds, letters, arrays, toggles, settings, X, bod, qs, extra, vattr, eattr,
         fattr, vcon, surface, totals, it_state, more, filename, attr_store) = snap
        self.filename = filename
        self._attr_store = attr_store          # graphics-only attributes (commands.attributes)
        self.surface = surface
        self.totals = totals            # the energies of the restored coordinates
        if self._iterator is not None:
            if it_state is None:
                self._iterator = None
            else:
                (self._iterator.cg_history, self._iterator.cg_S_old, self._iterator.cg_f_old,
                 self._iterator.pressures_valid) = it_state
        self.variables.clear()
        self.variables.update(vars_)
        self.commands = cmds
        self.letters = letters
        self.arrays = arrays
        self.toggles = toggles
        self.settings = settings
        s = self.surface
        if s is not None:
            s.X = X
            if bod is not None:
                b = s.bodies
                b.target, b.pressure, b.volconst, b.density, b.lagrange = bod
            for k, (t, m, kind, p, tol, methods) in qs.items():
                q = s.quantities[k]
                q.target, q.modulus, q.kind, q.pressure, q.tolerance = t, m, kind, p, tol
                q.methods[:] = methods          # set/unset element membership
            s.extra = extra
            s.vattr = vattr
            s.eattr = eattr
            s.fattr = fattr
            s.vcon = vcon
            s.econ, s.fcon, s.gravity_constant, s.sq_curvature_modulus = more

    # -- evaluation ------------------------------------------------------------------
    def recalc(self, keep_cg: bool = False, reposition: bool = False, totals=None) -> None:
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
        self._iterator.settings = IterateSettings.from_mappings(self.settings, self.toggles)
        return self._iterator

    def reset_cg(self) -> None:
        """Forget the conjugate-gradient history."""
        if self._iterator is not None:
            self._iterator.cg_history = None

    def g(self, n: int = 1, callback=None, echo: bool = False, progress=None) -> list:
        """Run ``n`` iteration steps; returns the list of step results.

        ``callback(result)`` is called after each step; returning True stops
        the run.  With ``echo`` the Evolver's progress lines are printed.
        ``progress``: a tqdm bar (True, False, or None for long runs at a
        terminal or in a notebook; never with ``echo``).
        """
        for name in UNSUPPORTED_MOTION:
            if self.toggles.get(name):
                raise UnsupportedError(f"g with {name} on", "only the plain gradient motion "
                                       "is implemented")
        if self.toggles.get("_effective_area_motion"):
            # REF's effective_area command also changes the motion (the top-section
            # keyword EFFECTIVE_AREA changes only the squared curvature)
            raise UnsupportedError("g with effective_area on", "the effective-area motion "
                                   "is not implemented")
        results = []
        if self.surface.nv == 0:                # e.g. after `t` removed everything (REF)
            self.write("WARNING 1051: No vertices. Did you forget to load a surface?\n\n")
            return results
        bar = None if echo else progress_bar(n, progress, "g")
        try:
            self._steps(n, callback, echo, results, bar)
        finally:
            if bar is not None:
                bar.close()
        return results

    def _steps(self, n, callback, echo, results, bar):
        for k in range(n, 0, -1):
            self.interp.tick()
            it = self.iterator
            r = it.step()
            # what the step did, kept by the session: the motion (the v_force,
            # v_oldx, v_velocity attributes), the optimized scale, the totals,
            # the iteration count and the time
            self._last_motion = r.motion
            if r.printed and not it.settings.fixed_scale:
                self.settings["scale"] = r.scale
            self.recalc(keep_cg=True, totals=r.totals)
            if r.printed:
                self.iteration_counter += 1
                self.total_time += r.scale
                r.energy, r.area = self.totals.energy, self.totals.total_area
            results.append(r)
            self.history.append((self.iteration_counter, r.energy, r.area))
            if bar is not None:
                bar.update(1)
                bar.set_postfix(energy=f"{r.energy:.10g}", refresh=False)
            L = self.settings.get("autochop_length", 0.0)
            if self.toggles.get("autochop") and L > 0:
                # autochop (spec §9.5): edges longer than autochop_length after
                # the move are bisected ("Autochopped N edges." before the line).
                # REF's choice of edges differs where it predicts lengths from
                # the unrestored motion (mound.fe); equal on cube.fe
                chop = long_edges(self.surface, L)
                if len(chop):
                    if self.surface.string:
                        nch = self._string_split(chop)
                    else:
                        new, nch = edge_divide(self.surface, chop)
                        self._replace_surface(new)
                    r.warnings.append(f"Autochopped {nch} edges.")
            if echo:
                for w in r.warnings:
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

    def go(self, n: int) -> None:
        """``g n`` at the prompt: steps with progress lines.

        Ctrl-C (SIGINT) during the run is deferred to the end of the current
        step: the step completes, the run stops and the surface is the one
        after that step."""
        with _deferred_sigint() as flag:
            self.g(n, echo=True, callback=lambda r: flag["hit"])
        if flag["hit"]:
            # the rest of the command (an enclosing loop too) is abandoned; the
            # surface is the one after the last complete iteration
            raise I.Interrupted("Interrupted: stopped after a complete iteration.")

    def bfgs(self, n: int, echo: bool = True, callback=None, progress=None):
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

    def newton(self, n: int, echo: bool = True, callback=None):
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

    def hessian(self, seek: bool = False, max_scale: float | None = None, echo: bool = True):
        """``hessian``: one Newton step on the constrained problem;
        ``hessian_seek [max]``: a line search along the Newton direction
        (scale at most ``max``, default 1).  Returns a :class:`StepResult`
        (:func:`pyevolver.evolve.newton.hessian_step`)."""
        self.no_string("hessian")
        if self.surface is None or self.surface.nv == 0:
            # (everything deleted; REF: "No vertices" warnings or unrelated errors)
            raise CommandError(f"{'hessian_seek' if seek else 'hessian'}: the surface has "
                               f"no vertices")
        it = self.iterator
        if not it.pressures_valid and len(_Constraints(self.surface)):
            raise CommandError("Pressures invalid. Do regular iteration before Hessian "
                               "to set pressures.")
        r = hessian_step(it, seek, max_scale, normal=it.settings.hessian_normal)
        self.recalc(totals=r.totals)
        if r.message == "infinite":
            raise CommandError("hessian: the Newton step gives a non-finite energy; "
                               "the surface is unchanged")
        r.energy, r.area = self.totals.energy, self.totals.total_area
        if echo:
            for w in r.warnings:
                self.write(w + "\n")
            if not self.toggles.get("quiet"):
                self.write("%3d. area: %#17.15g energy: %#17.15g\n" % (1, r.area, r.energy))
        return r

    # -- mesh upkeep ------------------------------------------------------------------
    def _replace_surface(self, new):
        self.surface = new
        self.recalc()

    def no_string(self, what, surface=None):
        """Refuse ``what`` by name on a string-model surface."""
        s = self.surface if surface is None else surface
        if s is not None and s.string:
            raise UnsupportedError(f"{what} in the string model")

    def _string_split(self, edges):
        from ..remesh.string import split_edges
        self._replace_surface(split_edges(self.surface, edges))
        return len(edges)

    def refine(self, echo=True):
        """``r``: refine every edge and facet (spec §8.1)."""
        from ..remesh import refine
        s = self.surface
        if s.string:
            self._string_split(np.nonzero(~s.eattr["no_refine"])[0])
        else:
            self._replace_surface(refine(s))
        if "edge_divide_length" in self.settings:
            self.settings["edge_divide_length"] /= 2
        if "areaweed_area" in self.settings:
            self.settings["areaweed_area"] /= 4
        if echo:
            self.note(self.counts_line())

    def counts_line(self):
        """``Vertices: ..  Edges: ..`` as after ``r`` and ``c``."""
        s = self.surface
        return (f"Vertices: {s.nv}  Edges: {s.ne}  Facets: {s.n_facets}  "
                f"Bodies: {s.bodies.n}  Facetedges: {self.internal('facetedge_count'):.0f}\n")

    def refine_edges(self, edges, echo=True):
        """``refine edges where ...``: bisect the given edges (spec §8)."""
        from ..remesh.edge_divide import edge_divide
        edges = np.asarray(edges, np.int64)
        if self.surface.string:
            n = self._string_split(np.unique(edges))
        else:
            new, n = edge_divide(self.surface, edges)
            self._replace_surface(new)
        if echo:
            self.report("Edges refined", n)

    def refine_facets(self, facets, echo=True):
        """``refine facets where ...``: split each facet into three at its
        centroid (REF's report "Facets refined: N")."""
        from ..remesh.notch import split_facets_at_centre
        self.no_string("refine facets")
        f = np.unique(np.asarray(facets, np.int64))
        self._replace_surface(split_facets_at_centre(self.surface, f))
        if echo:
            self.report("Facets refined", len(f))

    def equiangulate(self, echo=True):
        """``u``: one equiangulation sweep (spec §8.2)."""
        from ..remesh.equiangulate import equiangulate
        if self.surface.string:
            raise CommandError("Cannot equiangulate string model.")      # REF's ERROR 2200
        new, n = equiangulate(self.surface)
        self._replace_surface(new)
        self.counts["equi"] = n                 # REF: the last sweep's flips
        if echo:
            self.note(f"Edges switched in equiangulation: {n}\n")
        return n

    def edgeswap(self, edges, echo=True):
        """``edgeswap gen``: flip the listed edges that are diagonals of
        quadrilaterals, whatever the angles (manual: EDGESWAP)."""
        from ..remesh.equiangulate import equiangulate
        self.no_string("edgeswap")
        only = np.zeros(self.surface.ne, bool)
        only[np.asarray(edges, np.int64)] = True
        new, n = equiangulate(self.surface, threshold=np.inf, only=only)
        self._replace_surface(new)
        if echo:
            self.report("Edges swapped", n)
        return n

    def _bisect(self, edges, echo):
        from ..remesh.edge_divide import edge_divide
        if self.surface.string:
            n = self._string_split(np.asarray(edges, np.int64))
        else:
            new, n = edge_divide(self.surface, edges)
            self._replace_surface(new)
        self._count("refine", n)                # REF: l and K accumulate, r does not
        if echo:
            self.note(f"New edges: {n}\n")
        return n

    def edge_divide_long(self, length, echo=True):
        """``l L``: bisect every edge longer than ``L`` once (spec §8)."""
        from ..remesh.edge_divide import long_edges
        n = self._bisect(long_edges(self.surface, length), echo)
        self.settings["edge_divide_length"] = length
        return n

    def skinny(self, angle, echo=True):
        """``K θ``: bisect the longest edge of facets with an angle below θ."""
        from ..remesh.edge_divide import skinny_edges
        self.no_string("K (skinny triangles)")
        return self._bisect(skinny_edges(self.surface, angle), echo)

    def notch(self, angle, echo=True):
        """``n θ``: subdivide the facets on edges sharper than θ (spec §8)."""
        from ..remesh.notch import notch
        self.no_string("notch")
        new, n = notch(self.surface, angle)
        self._replace_surface(new)
        self._count("notch", n)
        if echo:
            self.note(f"Number of edges notched: {n}\n")
        return n

    def pop_edges(self, echo=True):
        """``O``: pop the edges with four facets (pyevolver.remesh.pop)."""
        from ..remesh.pop import pop_edges
        new, n = pop_edges(self.surface)
        self._replace_surface(new)
        self.counts["edge_pop"] = n             # REF: a later O with no pops prints 0
        if echo:
            self.note(f"Edges popped: {n}\n")
        return n

    def _count(self, key, n):
        self.counts[key] = self.counts.get(key, 0) + n

    def delete_short_edges(self, length, echo=True):
        """``t L`` / ``edgeweed L``: delete edges shorter than ``L`` (spec §8.4)."""
        from ..remesh.delete_edges import delete_short_edges
        self.no_string("t (edge weeding)")
        new, n = delete_short_edges(self.surface, length)
        self._replace_surface(new)
        self._count("edge_delete", n)
        if echo:
            self.note(f"Deleted edges: {n}\n")
        return n

    def delete_elements(self, kind, items, echo=True):
        """``delete edges ...`` / ``delete facets ...``: delete the edges (or,
        per facet, its shortest deletable side) as ``t`` / ``w`` do."""
        from ..remesh.delete_edges import delete_edges, delete_facets
        self.no_string("delete")
        fn = delete_edges if kind == "edge" else delete_facets
        new, n = fn(self.surface, items)
        self._replace_surface(new)
        self._count("edge_delete", n)
        return n

    def jiggle(self, temperature=None, echo=True):
        """``j [T]``: move every vertex that is not FIXED or on a parametric
        boundary by a Gaussian displacement of deviation T × mean edge length
        (T defaults to ``jiggle_temperature``); vertices on constraints are
        projected back.  Seeded by ``random_seed`` (pyevolver's generator,
        so the numbers differ from the Evolver's)."""
        s = self.surface
        T = self.settings["jiggle_temperature"] if temperature is None else float(temperature)
        if not math.isfinite(T):
            raise CommandError(f"j: the temperature must be a finite number, got {T:g}")
        t = self.totals
        sigma = T * (float(np.mean(t.edge_length)) if s.ne else 0.0)
        move = ~s.vattr["fixed"]
        if "boundary" in s.vattr:
            move &= s.vattr["boundary"] == 0
        new = copy.copy(s)
        new.__dict__.pop("_lift_cache", None)
        new.X = s.X.copy()
        idx = np.nonzero(move)[0]
        new.X[idx, :s.sdim] += sigma * self.rng.standard_normal((len(idx), s.sdim))
        self._project_or_fail(new, idx)
        self._replace_surface(new)
        if echo:
            self.write("One jiggle done.\n")

    def weed(self, area, echo=True):
        """``w A`` / ``areaweed A``: remove facets of area below ``A`` by
        deleting one of their edges, shortest first (spec §8.4)."""
        from ..remesh.delete_edges import weed_small_facets
        if self.surface.string:
            raise CommandError("Can only do area weed on soapfilm model.")   # REF's ERROR 1339
        new, n = weed_small_facets(self.surface, area)
        self._replace_surface(new)
        self._count("edge_delete", n)
        if echo:
            self.note(f"Skinny triangles weeded: {n}\n")
        return n

    def vertex_average(self, mode="V", echo=True):
        """``V``, ``rawv``, ``rawestv``: vertex averaging (spec §8.3)."""
        from ..remesh.vertex_average import vertex_average
        if self.surface.string:
            from ..remesh.string import vertex_average as string_average
            self._replace_surface(string_average(self.surface, mode))
        else:
            self._replace_surface(vertex_average(self.surface, mode))
        if echo:
            self.note("Vertex averaging done.\n")

    def refresh(self):
        if self.toggles.get("autorecalc", 1):
            self.recalc(keep_cg=True)

    @property
    def total_energy(self):
        return self.totals.energy

    @property
    def total_area(self):
        return self.totals.total_area

    # -- variables ----------------------------------------------------------------------
    def set_variable(self, name, value):
        if name in READ_ONLY:
            raise CommandError(f"'{name}' is read-only")
        if name in self.commands:
            del self.commands[name]
        if name in self.settings or name in ("gravity_constant", "sq_curvature_modulus"):
            value = I.as_float(value, f"'{name}'")     # settings are numbers
        if name in self.settings:
            if name == "random_seed":
                self.rng = np.random.default_rng(I.as_int(value, "random_seed") & (2**63 - 1))
            self.settings[name] = value
            return
        if name == "gravity_constant":
            self.surface.gravity_constant = float(value)
        if name == "sq_curvature_modulus" and self.surface is not None:
            self.surface.sq_curvature_modulus = float(value)
            return
        if self.surface is not None and name in self.surface.quantities:
            raise CommandError(f"'{name}' is a quantity; assign to {name}.target or "
                               f"{name}.modulus")
        self.variables[name] = value
        proc = getattr(self, "on_assign_call", {}).get(name)
        if proc is not None and proc in self.commands:
            # PARAMETER name ... ON_ASSIGN_CALL proc: run it after each assignment
            busy = self.__dict__.setdefault("_on_assign_busy", set())
            if name not in busy:
                busy.add(name)
                try:
                    self.interp.run_proc(self.commands[proc], [])
                finally:
                    busy.discard(name)

    def internal(self, name):
        s = self.surface
        t = self.totals
        if name in self.settings:
            return self.settings[name]
        if name in N.CONSTANTS:
            return N.CONSTANTS[name]
        if s is not None and name in s.quantities:
            return I.QRef(name)
        for cid, cname in getattr(s, "constraint_names", {}).items():
            if cname == name:
                return float(cid)
        for bid, bname in getattr(s, "boundary_names", {}).items():
            if bname == name:
                return float(bid)
        if name in self.toggles or name in I.TOGGLES:
            return float(self.toggles.get(name, I.TOGGLE_DEFAULTS.get(name, 0)))
        if s is None:
            raise ExpressionError(f"undefined name '{name}' (no surface loaded)")
        simple = {
            "total_energy": lambda: t.energy,
            "total_area": lambda: t.total_area,
            "total_length": lambda: t.total_length,
            "vertex_count": lambda: s.nv, "edge_count": lambda: s.ne,
            "facet_count": lambda: s.n_facets, "body_count": lambda: s.bodies.n,
            "facetedge_count": lambda: self._facetedge_count(),
            "space_dimension": lambda: s.sdim, "surface_dimension": lambda: 1 if s.string else 2,
            "high_constraint": lambda: max(s.constraints, default=0),
            "high_boundary": lambda: max(s.boundaries, default=0),
            "torus": lambda: 1 if s.periods is not None else 0,
            "datafilename": lambda: self.filename,
            "gravity_constant": lambda: s.gravity_constant,
            "sq_curvature_modulus": lambda: s.sq_curvature_modulus,
            "g": lambda: s.gravity_constant,
            "iteration_counter": lambda: self.iteration_counter,
            "total_time": lambda: self.total_time,
            "equi_count": lambda: self.counts.get("equi", 0),
            "edge_delete_count": lambda: self.counts.get("edge_delete", 0),
            "vertex_pop_count": lambda: self.counts.get("vertex_pop", 0),
            "edge_pop_count": lambda: self.counts.get("edge_pop", 0),
            "notch_count": lambda: self.counts.get("notch", 0),
            "refine_count": lambda: self.counts.get("refine", 0), "where_count": lambda: 0,
            "random": lambda: float(self.rng.random()),
            "quantity_count": lambda: len(s.quantities),
            "symmetry_group": lambda: 0, "simplex_representation": lambda: 0,
            "lagrange_order": lambda: 1, "linear": lambda: 1, "quadratic": lambda: 0,
            "lagrange": lambda: 0,
            "date_and_time": lambda: time.strftime("%a %b %d %H:%M:%S %Y"),
            # REF: "total elapsed Evolver execution time in seconds"; here the
            # processor time of the process (REF prints 0.005 right after loading cube.fe)
            "clock": time.process_time,
        }
        fn = simple.get(name)
        if fn is None:
            raise ExpressionError(f"undefined name '{name}'")
        v = fn()
        return v if isinstance(v, str) else float(v)

    def _facetedge_count(self):
        s = self.surface
        if s.string:
            from ..model.string import facetedge_count
            return facetedge_count(s)
        return 3 * s.nf

    # -- elements ------------------------------------------------------------------------
    def count(self, kind):
        s = self.surface
        return {"vertex": s.nv, "edge": s.ne, "facet": s.n_facets, "body": s.bodies.n}[kind]

    def element(self, kind, index):
        k = I.as_int(index, f"a {kind} index")
        n = self.count(kind)
        sign = -1 if k < 0 else 1
        attrs = {"vertex": "vattr", "edge": "eattr", "facet": "fattr"}.get(kind)
        ids = getattr(self.surface, attrs).get("id") if attrs else None
        if ids is not None:                     # ids with gaps after deletions
            hit = np.nonzero(ids == abs(k))[0]
            if k == 0 or not len(hit):
                raise ExpressionError(f"{kind}[{k}] does not exist")
            return I.ElemRef(kind, int(hit[0]), sign)
        if k == 0 or abs(k) > n:
            raise ExpressionError(f"{kind}[{k}] does not exist ({kind} ids are 1..{n})")
        return I.ElemRef(kind, abs(k) - 1, sign)

    def generate(self, gen, env):
        """Elements of a generator, with its ``where`` filter applied."""
        els = self._gen_base(gen.base, env)
        if gen.where is None:
            return els
        out = []
        tick = self.interp.tick
        for el in els:
            tick()
            with env.element(el, gen.var):
                v = gen.where.ev(env)
            if I.is_true(v):
                out.append(el)
        return out

    def _gen_base(self, base, env):
        tag = base[0]
        if "facetedge" in base[1:3]:
            raise UnsupportedError("facetedge elements")
        if tag == "var":
            el = env.lookup(base[1])
            if not isinstance(el, I.ElemRef):
                raise ExpressionError(f"'{base[1]}' is not an element")
            return [el]
        if tag == "all":
            return [I.ElemRef(base[1], i) for i in range(self.count(base[1]))]
        if tag == "index":
            return [self.element(base[1], env.session.interp.value(base[2]))]
        if tag == "sub":
            parents = self._gen_base(base[1], env)
        else:
            parent = env.lookup(base[1])
            if not isinstance(parent, I.ElemRef):
                raise ExpressionError(f"'{base[1]}' is not an element")
            parents = [parent]
        kind, idx = base[2], base[3]
        out = []
        for p in parents:
            subs = self.sub_elements(p, kind)
            if idx is not None:
                k = I.as_int(env.session.interp.value(idx), f"a {kind} index")
                if k < 1 or k > len(subs):
                    raise ExpressionError(f"{p}.{kind}[{k}] does not exist")
                subs = [subs[k - 1]]
            out.extend(subs)
        return out

    def sub_elements(self, el, kind):
        self._check_alive(el)
        s = self.surface
        i = el.i
        if s.string and "facet" in (el.kind, kind) and el.kind != "body":
            return self._string_sub_elements(el, kind)
        if el.kind == "vertex":
            if kind == "edge" and "ring_time" in s.eattr:
                from ..model.string import vertex_edges
                return [I.ElemRef("edge", e, g) for e, g in vertex_edges(s, i)]
            if kind == "edge":
                # oriented away from the vertex (oid < 0 where it is the head),
                # in the Evolver's ring order (surface.vertex_rings)
                from ..model.records import vertex_edge_rank
                es, end = np.nonzero(s.E == i)
                es = es[np.argsort(vertex_edge_rank(s)[es, end], kind="stable")]
                es = list(dict.fromkeys(es.tolist()))
                return [I.ElemRef("edge", int(e), 1 if s.E[e, 0] == i else -1) for e in es]
            if kind == "facet":
                from ..model.records import vertex_facet_rank
                fs, corner = np.nonzero(s.F == i)
                fs = fs[np.argsort(vertex_facet_rank(s)[fs, corner], kind="stable")]
                return [I.ElemRef("facet", int(f)) for f in dict.fromkeys(fs.tolist())]
        if el.kind == "edge":
            if kind == "vertex":
                a, b = s.E[i]
                if el.sign < 0:
                    a, b = b, a
                return [I.ElemRef("vertex", int(a)), I.ElemRef("vertex", int(b))]
            if kind == "facet":
                # oriented like the edge: oid < 0 where the facet runs against it
                from ..geometry.kernels import edge_index
                idx, sgn = edge_index(s.FE)
                out = []
                for f in np.nonzero((idx == i).any(axis=1))[0]:
                    g = int(sgn[f][np.nonzero(idx[f] == i)[0][0]]) * el.sign
                    out.append(I.ElemRef("facet", int(f), g))
                # REF's loop order of a two-facet edge: the facet running along
                # the edge first, unless the loop is known to start with the
                # other (surface.along_first)
                from ..model.records import along_first
                first = 1 if len(out) != 2 or along_first(s)[i] else -1
                out.sort(key=lambda r: -r.sign * el.sign * first)
                return out
        if el.kind == "facet":
            from ..geometry.kernels import edge_index
            if kind == "vertex":
                return [I.ElemRef("vertex", int(v)) for v in s.F[i]]
            if kind == "edge":
                idx, sgn = edge_index(s.FE[i])
                return [I.ElemRef("edge", int(e), int(g)) for e, g in zip(idx, sgn)]
            if kind == "body":
                col = s.bodies.facet_matrix[:, i].tocoo()
                return [I.ElemRef("body", int(b)) for b in col.row]
        if el.kind == "body" and kind == "facet":
            row = s.bodies.facet_matrix.getrow(i).tocoo()
            return [I.ElemRef("facet", int(f), int(np.sign(v))) for f, v in zip(row.col, row.data)]
        raise ExpressionError(f"{el.kind} has no {kind}s")

    def _string_sub_elements(self, el, kind):
        """Facet navigation in the string model (facets are edge chains)."""
        from ..model import string as SM
        s = self.surface
        i = el.i
        if el.kind == "facet":
            if kind == "vertex":
                return [I.ElemRef("vertex", v) for v in SM.chain_vertices(s, i, el.sign)]
            if kind == "edge":
                enc = SM.chain(s, i)
                if el.sign < 0:
                    enc = ~enc[::-1]
                return [I.ElemRef("edge", int(e if e >= 0 else ~e), 1 if e >= 0 else -1)
                        for e in enc]
            if kind == "body":
                col = s.bodies.facet_matrix[:, i].tocoo()
                return [I.ElemRef("body", int(b)) for b in col.row]
        if el.kind == "edge" and kind == "facet":
            return [I.ElemRef("facet", f, g * el.sign) for f, g in SM.facets_of_edge(s, i)]
        if el.kind == "vertex" and kind == "facet":
            owner, e, _, _, _ = SM.facet_entries(s)
            mine = (s.E[e] == i).any(axis=1)
            return [I.ElemRef("facet", int(f)) for f in np.unique(owner[mine])]
        raise ExpressionError(f"{el.kind} has no {kind}s")

    # -- attributes ------------------------------------------------------------------------
    def _check_alive(self, el):
        """An element reference kept across a command that removed elements
        (``foreach ... do { delete ...; print vv.id }``) may point past the
        end: refused by name."""
        if el.kind in ("vertex", "edge", "facet", "body") and el.i >= self.count(el.kind):
            raise ExpressionError(f"the {el.kind} no longer exists (deleted by this command)")

    def get_attr(self, base, name, idx):
        from ..commands import attributes as A
        if isinstance(base, A.ConstraintAt):
            return A.constraint_attr(self, base, name, idx)
        if name in ("on_quantity", "on_method_instance"):
            return A.on_quantity(self, base, name, idx)
        if idx is not None:                     # indices are integers (C truncation)
            idx = tuple(I.as_int(j, f"the index of '{name}'") for j in idx) \
                if isinstance(idx, tuple) else I.as_int(idx, f"the index of '{name}'")
        if isinstance(base, I.QRef):
            return self._quantity_attr(base.name, name)
        if not isinstance(base, I.ElemRef):
            raise ExpressionError(f"'.{name}' needs an element or a quantity")
        s = self.surface
        t = self.totals
        k, i = base.kind, base.i
        self._check_alive(base)
        eid = float(s.ids(k)[i]) if k in ("vertex", "edge", "facet") else float(i + 1)
        if name in ("id",):
            return eid
        if name == "oid":
            return eid * base.sign
        if name == "original":
            arr = {"vertex": s.vattr, "edge": s.eattr, "facet": s.fattr}.get(k, {}).get("original")
            if k == "body":
                return float(s.bodies.original[i])
            return float(arr[i]) if arr is not None else 0.0     # 0: no original (REF)
        if (k, name) in s.extra:
            arr = s.extra[(k, name)]
            conv = int if self.attr_types.get((k, name)) == "integer" else float
            if arr.ndim == 1:
                return conv(arr[i])
            return conv(arr[(i,) + self._attr_pos(k, name, arr, idx)])
        if name == "show":          # the default show criteria (graphics are not drawn)
            if k == "facet":
                return 1.0
            if k == "edge":
                return float(bool(s.eattr["fixed"][i]) or
                             len(self.sub_elements(base, "facet")) != 2)
        from ..commands import attributes as A
        v = A.element_attr(self, base, name, idx)
        if v is not A.MISSING:
            return v
        if s.sdim == 2 and name in ("z", "x3") and k in ("vertex", "edge", "facet"):
            raise ExpressionError("Coordinate dimension exceeds space dimension.")  # REF 2475
        if k == "vertex":
            coords = {"x": 0, "y": 1, "z": 2, "x1": 0, "x2": 1, "x3": 2}
            if name == "x" and idx is not None:          # x[2] is y
                j = int(idx) if not isinstance(idx, tuple) else -1
                if j < 1 or j > s.sdim:
                    raise ExpressionError(f"vertex x[{j}]: index outside 1..{s.sdim}")
                return float(s.X[i, j - 1])
            if name in coords:
                return float(s.X[i, coords[name]])
            if name == "__x" and idx is not None:
                return float(s.X[i, int(idx) - 1])
            if name == "__x":
                return N.array_value(s.X[i, :s.sdim])
            if name == "fixed":
                return float(s.vattr["fixed"][i])
            if name in ("on_constraint", "hit_constraint"):
                m = s.vcon.get(int(idx))
                return float(m[i]) if m is not None else 0.0
            if name == "on_boundary":
                b = s.vattr.get("boundary")
                return float(b is not None and b[i] == int(idx))
            if name == "valence":
                return float(np.count_nonzero((s.E == i).any(axis=1)))
            if name in ("vertexnormal", "vertex_normal"):
                if isinstance(idx, tuple):
                    raise ExpressionError(f"vertex {name} is a vector; index it as {name}[i]")
                from ..geometry.kernels import vertex_normals
                from ..model.records import vertex_facet_rank
                if s.nf == 0:
                    raise UnsupportedError("vertex_normal in the string model")
                nrm = vertex_normals(s.F, t.facet_N2, s.nv, vertex_facet_rank(s))[i]
                if idx is None:
                    return N.array_value(nrm)
                j = int(idx)
                if j < 1 or j > s.sdim:
                    raise ExpressionError(f"{name}[{j}]: index outside 1..{s.sdim}")
                return float(nrm[j - 1])
            if name in ("p1", "p2") and "params" in s.vattr:
                return float(s.vattr["params"][i, int(name[1]) - 1])
        elif k == "edge":
            if name == "length":
                return float(t.edge_length[i])
            if name in ("x", "y", "z"):
                return float(t.edge_vec[i, "xyz".index(name)] * base.sign)
            if name == "edge_vector":
                if idx is None:
                    return N.array_value(t.edge_vec[i, :s.sdim] * base.sign)
                if isinstance(idx, tuple):
                    raise ExpressionError("edge_vector takes one index")
                j = int(idx)
                if j < 1 or j > s.sdim:
                    raise ExpressionError(f"edge_vector[{j}]: index outside 1..{s.sdim}")
                return float(t.edge_vec[i, j - 1] * base.sign)
            if name in ("tension", "density"):
                return float(s.edge_tension[i])
            if name == "fixed":
                return float(s.eattr["fixed"][i])
            if name == "no_refine":
                return float(s.eattr["no_refine"][i])
            if name in ("on_constraint", "hit_constraint"):
                m = s.econ.get(int(idx))
                return float(m[i] != 0) if m is not None else 0.0
            if name == "on_boundary":
                b = s.eattr.get("boundary")
                return float(b is not None and b[i] == int(idx))
            if name == "valence":
                return float(len(self.sub_elements(base, "facet")))
            if name == "orientation":
                return float(base.sign)
            if name in ("color", "colour"):
                c = s.eattr.get("color")
                return float(c[i]) if c is not None else 0.0
        elif k == "facet":
            if name == "area":
                return float((t.sfacet_area if s.string else t.facet_area)[i])
            if s.string and name in ("x", "y", "z", "valence"):
                if name == "valence":
                    return float(s.sf_ptr[i + 1] - s.sf_ptr[i])
                raise UnsupportedError(f"facet normal ({name}) in the string model")
            if name in ("x", "y", "z"):
                j = "xyz".index(name)
                if s.periods is None and s.sdim == 3:
                    # the Evolver's order of operations: (side 1) x (side 2), so
                    # signed zeros come out as in its exporters' output
                    a, b, c = s.X[s.F[i]]
                    return float(0.5 * np.cross(b - a, c - b)[j] * base.sign)
                return float(0.5 * t.facet_N2[i, j] * base.sign)
            if name in ("tension", "density"):
                return float(s.facet_tension[i])
            if name == "fixed":
                return float(s.fattr["fixed"][i])
            if name in ("on_constraint", "hit_constraint"):
                m = s.fcon.get(int(idx))
                return float(m[i]) if m is not None else 0.0
            if name in ("color", "colour", "frontcolor", "backcolor"):
                key = name.replace("colour", "color")
                c = s.fattr.get("backcolor" if key == "backcolor" else "frontcolor")
                if c is None:
                    c = s.fattr.get("color")
                return float(c[i]) if c is not None else 15.0     # white (REF default)
            if name == "valence":
                return 3.0
            if name in ("frontbody", "backbody"):
                # the body the facet bounds positively (front) or negatively
                col = s.bodies.facet_matrix[:, i].tocoo()
                want = 1 if name == "frontbody" else -1
                hit = [int(b) + 1 for b, v in zip(col.row, col.data) if np.sign(v) == want]
                return float(hit[0]) if hit else 0.0
        elif k == "body":
            b = s.bodies
            if name == "volume":
                return float(t.volumes[i])
            if name == "target":
                return float(b.target[i]) if not math.isnan(b.target[i]) else \
                    A.unset_value(self, i, "target", 0.0)
            if name == "volconst":
                return float(b.volconst[i])
            if name == "pressure":
                if not math.isnan(b.pressure[i]):
                    return float(b.pressure[i])
                return A.unset_value(self, i, "pressure", float(b.lagrange[i]))
            if name == "density":
                return float(b.density[i])
            if name == "fixed":
                return float(not math.isnan(b.target[i]))
        if name in I._KIND and idx is not None:       # ff.edge[2], ee.vertex[1]
            kind = I._KIND[name]
            if kind == "facetedge":
                raise UnsupportedError("facetedge elements")
            subs = self.sub_elements(base, kind)
            j = int(idx)
            if j < 1 or j > len(subs):
                raise ExpressionError(f"{base}.{kind}[{j}] does not exist ({k} {int(eid)} has "
                                      f"{len(subs)} {kind}{'s' if len(subs) != 1 else ''})")
            return subs[j - 1]
        if name in s.quantities and k in ("vertex", "edge", "facet"):
            return A.element_quantity_value(self, base, name)
        raise ExpressionError(f"{k} has no attribute '{name}'")

    @staticmethod
    def _attr_pos(k, name, arr, idx):
        """0-based position inside an array attribute from 1-based indices."""
        if idx is None:
            raise ExpressionError(f"{k} attribute '{name}' is an array; index it as "
                                  f"{name}[i]")
        idx = idx if isinstance(idx, tuple) else (idx,)
        if len(idx) != arr.ndim - 1:
            raise ExpressionError(f"{k} attribute '{name}' needs {arr.ndim - 1} "
                                  f"ind{'ices' if arr.ndim > 2 else 'ex'}, got {len(idx)}")
        pos = []
        for j, n in zip(idx, arr.shape[1:]):
            if isinstance(j, str) or int(j) < 1 or int(j) > n:
                raise ExpressionError(f"{k} attribute {name}[{j}]: index outside 1..{n}")
            pos.append(int(j) - 1)
        return tuple(pos)

    def _quantity_attr(self, qname, name):
        q = self.surface.quantities[qname]
        if q.kind == "instance" and name not in ("value", "modulus"):
            raise ExpressionError(f"method instance {qname} has no attribute '{name}' "
                                  f"(possible method instance attributes: value, modulus)")
        if name == "value":
            return float(self.totals.quantity_values[qname])
        if name == "target":
            return float(q.target)
        if name == "modulus":
            return float(q.modulus)
        if name == "pressure":
            return float(q.pressure)
        if name == "tolerance":
            return float(q.tolerance)
        from ..commands import attributes as A
        return A.quantity_attr(self, q, name)

    def set_attr(self, base, name, idx, value):
        if idx is not None:
            idx = tuple(I.as_int(j, f"the index of '{name}'") for j in idx) \
                if isinstance(idx, tuple) else I.as_int(idx, f"the index of '{name}'")
        if isinstance(value, str):
            raise CommandError(f"cannot assign a string to '.{name}'")
        s = self.surface
        if isinstance(value, N.ArrayValue):
            key = (getattr(base, "kind", None), name)
            arr = s.extra.get(key)
            if arr is None or idx is not None or arr.shape[1:] != value.shape:
                raise CommandError(f"cannot assign an array of shape {list(value.shape)} to "
                                   f"'.{name}'")
            arr[base.i] = np.asarray(value)
            return
        value = I.as_float(value, f"the value of '.{name}'")
        if isinstance(base, I.QRef):
            q = s.quantities[base.name]
            if name in ("target", "modulus", "tolerance"):
                setattr(q, name, value)
                return
            raise CommandError(f"quantity attribute '{name}' is read-only")
        if not isinstance(base, I.ElemRef):
            raise CommandError(f"'.{name}' needs an element or a quantity")
        self._check_alive(base)
        k, i = base.kind, base.i
        from ..commands import attributes as A
        if (k, name) not in s.extra and A.set_element_attr(self, base, name, idx, value):
            return
        if (k, name) in s.extra:
            arr = s.extra[(k, name)]
            if self.attr_types.get((k, name)) == "integer":
                value = float(int(value))            # C conversion truncates
            if arr.ndim == 1:
                arr[i] = value
            elif idx is None:
                arr[i] = value                  # every entry (REF: set vertex vec 0)
            else:
                arr[(i,) + self._attr_pos(k, name, arr, idx)] = value
            return
        if k == "vertex" and name in ("x", "y", "z", "x1", "x2", "x3"):
            j = {"x": 0, "y": 1, "z": 2, "x1": 0, "x2": 1, "x3": 2}[name]
            if name == "x" and idx is not None:
                j = int(idx) - 1 if not isinstance(idx, tuple) else -1
                if j < 0 or j >= s.sdim:
                    raise CommandError(f"vertex x[{j + 1}]: index outside 1..{s.sdim}")
            if not math.isfinite(value):
                raise CommandError(f"vertex coordinates must be finite numbers, got {value:g}")
            s.X[i, j] = value
            A.cache(self).touch(self)           # attributes read the live coordinates
            return
        if k == "body":
            b = s.bodies
            if name == "target":
                b.target[i] = value
                b.pressure[i] = np.nan
                return
            if name == "volconst":
                b.volconst[i] = value
                return
            if name == "pressure":
                b.pressure[i] = value
                b.target[i] = np.nan
                return
            if name == "density":
                b.density[i] = value
                if value:           # REF: a body density switches gravity on
                    self.toggles["gravity"] = 1
                return
        if k == "facet" and name in ("tension", "density"):
            s.fattr["tension"][i] = value
            return
        if k in ("edge", "facet") and name in ("color", "colour", "frontcolor", "backcolor"):
            attrs, n = (s.eattr, s.ne) if k == "edge" else (s.fattr, self.count(k))
            name = name.replace("colour", "color")
            default = 0 if k == "edge" else 15
            value = I.as_int(value, f"a {name}")
            if abs(value) > 2**31 - 1:
                raise CommandError(f"{name} {value} is out of range")
            if "color" not in attrs:
                attrs["color"] = np.full(n, default, np.int64)
            if name == "color":
                for key in ("color", "frontcolor", "backcolor"):
                    if key in attrs:
                        attrs[key][i] = int(value)
            elif name == "frontcolor":
                if k == "facet" and "backcolor" not in attrs:    # the back keeps its colour
                    attrs["backcolor"] = attrs["color"].copy()
                for key in ("color", "frontcolor"):
                    if key in attrs:
                        attrs[key][i] = int(value)
            else:
                if name not in attrs:
                    attrs[name] = attrs["color"].copy()
                attrs[name][i] = int(value)
            return
        if k in ("vertex", "edge", "facet") and name in ("fixed", "no_refine"):
            attrs = {"vertex": s.vattr, "edge": s.eattr, "facet": s.fattr}[k]
            if name not in attrs:
                attrs[name] = np.zeros(self.count(k), bool)
            attrs[name][i] = bool(value)
            return
        if k == "edge" and name in ("tension", "density"):
            s.eattr.setdefault("tension", np.zeros(s.ne))[i] = value
            return
        raise CommandError(f"cannot assign to {k} attribute '{name}'")

    def set_elements(self, gen, attr, expr, env, unset, idx=None):
        from ..commands import attributes as A
        els = self.generate(gen, env)
        qname = A.membership_name(self, gen.kind, attr, expr)
        if qname is not None:
            A.set_membership(self, gen.kind, els, qname, not unset)
            return
        if A.is_flag(gen.kind, attr) and (expr is None or unset):
            for el in els:         # boolean attributes: set = 1, unset = 0
                self.set_attr(el, attr, None, 0.0 if unset else 1.0)
            return
        if attr in ("fixed", "no_refine") and (expr is None or unset):
            if gen.kind == "body":
                raise CommandError(f"bodies cannot be {'un' if unset else ''}set {attr}; "
                                   f"use 'set body target expr' / 'unset body target'")
            for el in els:
                self.set_attr(el, attr, None, 0.0 if unset else 1.0)
            return
        if unset:
            if attr == "boundary" and expr is not None:
                A.unset_boundary(self, els, self.interp.value(expr))
                return
            if attr in ("constraint",) and expr is not None:
                self.unset_constraint(els, int(self.interp.value(expr)))
                return
            if attr == "density" and gen.kind == "body":
                return      # REF: neither the printed density nor the energy changes
            if attr in ("target", "pressure") and gen.kind == "body":
                b = self.surface.bodies
                arr = getattr(b, attr)
                for el in els:      # REF still prints the old value (volfixed 0)
                    A.remember_unset(self, el.i, attr, arr[el.i])
                    arr[el.i] = np.nan
                return
            if (gen.kind, attr) in self.surface.extra:
                for el in els:
                    self.set_attr(el, attr, None, 0.0)
                return
            raise UnsupportedError(f"unset {gen.kind} {attr}")
        if expr is None:
            raise UnsupportedError(f"set {gen.kind} {attr} (without a value)")
        if attr == "constraint":
            self.set_constraint(els, self.interp.value(expr))
            A.cache(self).touch(self)           # projected vertices moved
            return
        # compute every value first, then assign (like the Evolver's set)
        vals = []
        ix = None if idx is None else self.interp.value(idx)
        for el in els:
            self.interp.tick()
            with env.element(el, gen.var):
                vals.append(self.interp.value(expr))
        for el, v in zip(els, vals):
            self.set_attr(el, attr, ix, v)
        if gen.kind == "vertex" and attr in ("x", "y", "z"):
            self._project_or_fail(self.surface, np.array([e.i for e in els], np.int64))
            A.cache(self).touch(self)

    def _project_or_fail(self, surface, idx):
        """Project vertices to their constraints; a projection that diverges
        fails the command (which leaves the surface as it was)."""
        bad = project_to_constraints(surface, idx)
        if len(bad):
            vid = surface.ids("vertex")[bad[0]]
            raise CommandError(f"the projection of vertex {vid} onto its constraints "
                               f"diverges")

    def set_constraint(self, els, cid):
        """``set gen constraint n``: put the elements on level-set constraint
        ``n`` (a number or a name from ``define constraint``); vertices are
        projected onto it at once (REF)."""
        s = self.surface
        if isinstance(cid, str) or int(cid) not in s.constraints:
            raise CommandError(f"constraint {cid if isinstance(cid, str) else int(cid)} "
                               f"is not defined")
        cid = int(cid)
        moved = []
        order = getattr(s, "con_order", None)
        for el in els:
            if order is not None and el.kind in ("vertex", "edge"):
                # REF lists a constraint set later after the element's others
                table = s.vcon if el.kind == "vertex" else s.econ
                had = [c for c in sorted(table) if table[c][el.i] and c != cid]
                seq = [c for c in order.get((el.kind, el.i), had) if c in had]
                order[(el.kind, el.i)] = seq + [c for c in had if c not in seq] + [cid]
            if el.kind == "vertex":
                m = s.vcon.setdefault(cid, np.zeros(s.nv, bool))
                m[el.i] = True
                moved.append(el.i)
            elif el.kind == "edge":
                s.econ.setdefault(cid, np.zeros(s.ne, np.int8))[el.i] = 1
            elif el.kind == "facet" and not s.string:
                s.fcon.setdefault(cid, np.zeros(s.nf, bool))[el.i] = True
            else:
                raise CommandError("constraints belong to vertices, edges and facets")
        if moved:
            project_to_constraints(s, np.array(moved, np.int64))

    def define_constraint(self, text):
        """``define constraint NAME [flags] formula: expr [energy: ...] [content:
        ...]`` at run time: a level-set constraint numbered after the existing
        ones and known by its name (REF: ``list`` shows the name,
        ``on_constraint NAME`` and ``set ... constraint NAME`` use it)."""
        import re
        from ..datafile.preprocess import Section
        from ..datafile.reader import Reader
        m = re.match(r"\s*define\s+constraint\s+([a-z_]\w*)(.*)\Z", text, re.I | re.S)
        if m is None:
            raise CommandError("define constraint: expected a name, e.g. "
                               "define constraint cc formula: x^2 + y^2 = 1")
        name, rest = m.group(1).lower(), m.group(2)
        arr = re.search(r"([a-z_]\w*)\s*\[", rest, re.I)
        if arr:
            raise UnsupportedError(f"array elements in constraint formulas ({arr.group(1)}[...] "
                                   f"in constraint {name})")
        s = self.surface
        names = getattr(s, "constraint_names", {})
        cid = next((c for c, n in names.items() if n == name), None)
        if cid is None:
            if name in self.variables or name in self.commands:
                raise CommandError(f"define constraint: '{name}' is already a variable or command")
            cid = max(s.constraints, default=0) + 1
        reader = Reader("<define constraint>", "")
        reader.scene.parameters = {k: v for k, v in self.variables.items()
                                   if isinstance(v, float)}
        reader._top(Section("top", f"constraint {cid} {rest}\n", 1, [1]))
        decl = reader.scene.constraints[cid]
        s.constraints = {**s.constraints, cid: decl}
        s.constraint_names = {**names, cid: name}
        if "global" in decl.flags:
            s.vcon[cid] = np.ones(s.nv, bool)
            s.econ[cid] = np.ones(s.ne, np.int8)
            project_to_constraints(s, np.arange(s.nv))

    def constraint_label(self, cid):
        """A constraint's number, or its name when defined at run time."""
        return getattr(self.surface, "constraint_names", {}).get(cid, str(cid))

    def _in_order(self, kind, i, cons):
        """An element's constraints in the order REF lists them: as the
        datafile line gave them, then those set later, in turn (``cons``:
        the constraints it is on, by number)."""
        order = getattr(self.surface, "con_order", None)
        seq = order.get((kind, i)) if order else None
        if not seq or len(cons) < 2:
            return cons
        first = [c for c in seq if c in cons]
        return first + [c for c in cons if c not in first]

    def _record_order(self, scene, surface):
        """The datafile order of the constraints of vertices and edges named
        with several (see :meth:`_in_order`)."""
        order = {}
        for kind, blk, n in (("vertex", scene.vertices, surface.nv),
                             ("edge", scene.edges, surface.ne)):
            for pos, attrs in blk.attrs.items():
                cids = [int(abs(v)) for kw, vals in attrs
                        if kw in ("constraint", "constraints") for v in vals]
                if len(cids) > 1 and cids != sorted(cids) and pos < n:
                    order[(kind, pos)] = cids
        surface.con_order = order

    def boundary_label(self, bid):
        """A boundary's number, or its name when declared by name."""
        return getattr(self.surface, "boundary_names", {}).get(bid, str(bid))

    def unset_constraint(self, els, cid):
        s = self.surface
        if cid not in s.vcon and cid not in s.econ and cid not in s.fcon:
            return
        for el in els:
            table = {"vertex": s.vcon, "edge": s.econ, "facet": s.fcon}.get(el.kind)
            if table is None:
                raise CommandError("constraints belong to vertices, edges and facets")
            m = table.get(cid)
            if m is not None:
                m[el.i] = 0

    def fix_elements(self, els, on):
        """``fix``/``unfix`` elements; returns how many changed."""
        n = 0
        for el in els:
            if el.kind == "body":
                raise CommandError("cannot fix or unfix bodies; to fix a volume use "
                                   "'set body target expr', to free it 'unset body target'")
            old = self.get_attr(el, "fixed", None)
            if bool(old) != bool(on):
                self.set_attr(el, "fixed", None, 1.0 if on else 0.0)
                n += 1
        return n

    def fix_name(self, name, on):
        """``fix quantity`` / ``unfix quantity``."""
        s = self.surface
        if name in s.quantities:
            q = s.quantities[name]
            if on:
                q.target = float(self.totals.quantity_values[name])
                q.kind = "fixed"
            else:
                q.kind = "info_only" if q.kind == "fixed" else q.kind
            return
        if name in self.variables:
            raise UnsupportedError(f"{'fix' if on else 'unfix'} {name} (optimizing parameters)")
        raise CommandError(f"{'fix' if on else 'unfix'}: '{name}' is not a quantity "
                           f"(expected: fix element_generator or fix quantity_name)")

    def define_attribute(self, kind, name, typ, shape):
        """``define vertex attribute name real[3]`` at run time."""
        s = self.surface
        if typ not in ("real", "integer"):
            raise UnsupportedError(f"{typ} element attributes", "real and integer are supported")
        if kind == "facetedge":           # declared; facetedges themselves are refused when used
            self.attr_types[(kind, name)] = typ
            return
        n = self.count(kind)
        key = (kind, name)
        new = np.zeros((n,) + tuple(shape)) if shape else np.zeros(n)
        old = s.extra.get(key)
        if old is not None:
            if old.shape == new.shape:
                self.attr_types[key] = typ
                return
            if old.ndim == new.ndim:               # resizing keeps the values
                sl = tuple(slice(0, min(a, b)) for a, b in zip(old.shape, new.shape))
                new[sl] = old[sl]
        s.extra[key] = new
        self.attr_types[key] = typ

    def read_file(self, name):
        """``read "file"``: run a command file (the current directory first,
        then the directories of EVOLVERPATH).  An error stops the file."""
        import os
        cands = [name]
        if not os.path.isabs(name):
            for d in os.environ.get("EVOLVERPATH", "").split(os.pathsep):
                if d:
                    cands.append(os.path.join(d, name))
        path = next((c for c in cands if os.path.exists(c)), None)
        if path is None:
            raise CommandError(f"read: cannot find file '{name}' (looked in the current "
                               f"directory and EVOLVERPATH)")
        if not os.path.isfile(path):       # /dev/zero, a FIFO, a directory: never read
            raise CommandError(f"read: '{path}' is not a regular file (a directory, "
                               f"device or pipe)")
        if len(self.interp.env.scopes) > MAX_NESTING:
            raise CommandError(f"read \"{name}\": files read each other too deeply")
        try:
            with open(path, encoding="latin-1") as fh:
                text = fh.read()
        except OSError as exc:
            raise CommandError(f"read: cannot read '{name}': {exc.strerror}") from None
        try:
            self.run(text, where=path, line=1, stop_on_error=True)
        except I.Quit:
            raise
        except PyEvolverError as exc:
            # like the Evolver, an error abandons the rest of the file; what
            # ran before it stays done
            self.write_err(f"{exc}\n")

    # -- listing ---------------------------------------------------------------------------------
    def list_elements(self, gen, env):
        """``list gen``: datafile-style lines in REF's formats (measured on
        evolver-nox-d: mound, catbody, column, twointor, string files)."""
        els = self.generate(gen, env)
        kind = gen.kind or (els[0].kind if els else None)
        fn = {"vertex": self._list_vertex, "edge": self._list_edge,
              "facet": self._list_facet, "body": self._list_body}.get(kind)
        if fn is None:
            return
        self.note({"vertex": "// Id               X                Y" +
                    ("               Z" if self.surface.sdim == 3 else ""),
                    "edge": "// Id    endpoints", "facet": "// Id    edges",
                    "body": "// Id    facets"}[kind] + "\n")
        for el in els:
            self.write(fn(el.i) + "\n")

    @staticmethod
    def _wrapped(items, indent):
        """Ids ``"%d "`` each, a `` \\`` line break after every tenth (REF)."""
        out = []
        for k, it in enumerate(items, 1):
            out.append(f"{it} ")
            if k % 10 == 0:
                out.append("\\\n" + " " * indent)
        return "".join(out)

    def _list_vertex(self, i):
        s = self.surface
        vid = s.ids("vertex")
        sd = s.sdim
        bnd = s.vattr.get("boundary")
        if bnd is not None and bnd[i]:
            b = s.boundaries[int(bnd[i])]
            par = " ".join(f"{p:17.15g}" for p in s.vattr["params"][i, :b.nparams])
            xyz = "".join(f" {x:17.15g}" for x in s.X[i, :sd])
            line = f"{vid[i]:3d}  {par}  boundary {self.boundary_label(int(bnd[i]))}  /* ({xyz}) */"
        else:
            line = f"{vid[i]:3d}  " + " ".join(f"{x:17.15g}" for x in s.X[i, :sd])
        cons = self._in_order("vertex", i, [c for c in sorted(s.vcon) if s.vcon[c][i]])
        if cons:
            line += "  constraints " + " ".join(map(self.constraint_label, cons)) + " "
        if s.vattr["fixed"][i]:
            line += " fixed "
        return line + self._extra_text("vertex", i)

    def _extra_text(self, kind, i):
        """Defined attributes as REF lists them: `` name value`` each (reals
        ``%2.15g``, integers ``%d``, arrays in braces)."""
        out = []
        for (k, name), arr in self.surface.extra.items():
            if k != kind:
                continue
            integer = self.attr_types.get((k, name)) == "integer"
            fmt = (lambda v: "%d" % int(v)) if integer else (lambda v: "%2.15g" % v)
            v = arr[i]
            if np.ndim(v):
                txt = "{" + ",".join(fmt(x) for x in np.ravel(v)) + "} "
            else:
                txt = fmt(v)
            out.append(f" {name} {txt}")
        return "".join(out)

    @staticmethod
    def _colour_name(c):
        names = {v: k for k, v in N.COLOURS.items() if k != "transparent"}
        return names.get(int(c), str(int(c)))

    def _list_edge(self, i):
        s = self.surface
        t = self.totals
        vid, eid = s.ids("vertex"), s.ids("edge")
        a, b = vid[s.E[i]]
        line = f"{eid[i]:3d}   {a:5d} {b:4d}    "
        w = s.eattr.get("wrap")
        if w is not None:
            line += " " + " ".join({0: "*", 1: "+", -1: "-"}.get(int(x), "?")
                                   for x in w[i, :s.sdim])
        ten = s.edge_tension[i]
        if ten != (1.0 if s.string else 0.0):
            line += f"  density {ten:g} "
        cons = self._in_order("edge", i, [c for c in sorted(s.econ) if s.econ[c][i]])
        if cons:
            line += "  constraints " + " ".join(
                ("-" if s.econ[c][i] < 0 else "") + self.constraint_label(c) for c in cons) + " "
        eb = s.eattr.get("boundary")
        if eb is not None and eb[i]:
            line += f"  boundary {self.boundary_label(int(eb[i]))} "
        if s.eattr["fixed"][i]:
            line += "fixed "
        if s.eattr["no_refine"][i]:
            line += " no_refine "
        col = s.eattr.get("color")
        if col is not None and col[i] != 0:
            line += f" color {self._colour_name(col[i])} "
        line += f" /*length {t.edge_length[i]:g}*/ "
        eorig = s.eattr.get("original")
        if eorig is not None and eorig[i] and eorig[i] != eid[i]:
            line += f" original {eorig[i]}"
        return line + self._extra_text("edge", i)

    def _list_facet(self, i):
        s = self.surface
        t = self.totals
        eid, fid = s.ids("edge"), s.ids("facet")
        if s.string:
            from ..model.string import chain
            enc = chain(s, i)
            edges = [int(eid[e]) if e >= 0 else -int(eid[~e]) for e in enc]
            area = t.sfacet_area[i]
        else:
            from ..geometry.kernels import edge_index
            idx, sgn = edge_index(s.FE[i])
            edges = [int(eid[e] * g) for e, g in zip(idx, sgn)]
            area = t.facet_area[i]
        attrs = ""
        cons = [c for c in sorted(s.fcon) if s.fcon[c][i]]
        if cons:
            attrs += " constraints " + " ".join(map(self.constraint_label, cons)) + "  "
        if not s.string and s.facet_tension[i] != 1.0:
            attrs += f" density {s.facet_tension[i]:g} "
        if s.fattr["fixed"][i]:
            attrs += " fixed "
        if s.fattr["no_refine"][i]:
            attrs += " no_refine "
        front = s.fattr.get("frontcolor", s.fattr.get("color"))
        back = s.fattr.get("backcolor", s.fattr.get("color"))
        fc = int(front[i]) if front is not None else 15
        bc = int(back[i]) if back is not None else 15
        if fc != 15:
            attrs += f"color {self._colour_name(fc)} "
        if bc != fc:
            attrs += (" " if attrs else "") + f"backcolor {self._colour_name(bc)} "
        line = (f"{fid[i]:3d}   " + self._wrapped(edges, 15) + attrs + (" " if attrs else "")
                + f"/*area {area:g}*/")
        orig = s.fattr["original"][i]
        if orig and orig != fid[i]:
            line += f" original {orig}"
        return line + self._extra_text("facet", i)

    def _list_body(self, i):
        s = self.surface
        t = self.totals
        b = s.bodies
        fid = s.ids("facet")
        ob, of, osg = b.occurrences
        sel = np.nonzero(ob == i)[0]
        facets = [int(fid[f] * g) for f, g in zip(of[sel], osg[sel])]
        line = f"{i + 1:3d}       " + self._wrapped(facets, 11)
        if not math.isnan(b.target[i]):
            line += (f" volume {b.target[i]:.15g}  /*actual: {t.volumes[i]:.15g}*/ "
                     f"lagrange_multiplier {b.lagrange[i]:.15g}  ")
        line += "centerofmass "
        if not math.isnan(b.pressure[i]):
            line += f"  pressure {b.pressure[i]:.15g}"
        if b.volconst[i]:
            line += f"  volconst {b.volconst[i]:.15g} "
        if b.density[i]:
            line += f"  density {b.density[i]:.15g} "
        return line + self._extra_text("body", i)

    # -- reports ------------------------------------------------------------------------------------
    def show_vol(self):
        """The ``v`` report (spec §9.3 formats)."""
        s = self.surface
        t = self.totals
        b = s.bodies
        lines = []
        qs = [q for q in s.quantities.values() if q.kind != "instance"]
        if not b.n and not qs:
            return "No bodies or quantities.\n"
        if b.n:
            lines.append("")
            lines.append("Body          target volume           actual volume          pressure")
            for i in range(b.n):
                name = str(i + 1)
                if not math.isnan(b.target[i]):
                    lines.append("%3s  %22.15g  %22.15g %17.15g" % (name, b.target[i], t.volumes[i],
                                                                   b.lagrange[i]))
                elif not math.isnan(b.pressure[i]):
                    lines.append("%3s            ------------     %22.15g %17.15g" % (
                        name, t.volumes[i], b.pressure[i]))
                else:
                    lines.append("%3s            ------------     %22.15g " % (name, t.volumes[i]))
        if qs:
            wdt = max([20] + [len(q.name) for q in qs])
            lines.append("")
            lines.append("%*s       target value           actual value                 pressure"
                         % (wdt, "Quantity"))
            for q in qs:
                v = t.quantity_values[q.name]
                if q.kind == "fixed":
                    lines.append("%*s  %22.15g  %22.15g  %17.15g" % (wdt, q.name, q.target, v,
                                                                    q.pressure))
                elif q.kind == "conserved":
                    lines.append("%*s     (conserved)     ----------------   %17.15g" % (
                        wdt, q.name, q.pressure))
                else:
                    lines.append("%*s         ---------      %22.15g" % (wdt, q.name, v))
        return "\n".join(lines) + "\n"
