"""The interpreter of the Evolver command language (spec §9): control
flow, user procedures and functions, variables and arrays.  Command words
and statements are looked up in :mod:`pyevolver.commands.registry`, where
their families (``remesh``, ``evolution``, ``toggles``, ``files``, ...)
register them; this module only dispatches.

Scripts are data: commands are parsed by :mod:`pyevolver.commands.parser`
into tuples and expression trees and executed here; nothing reaches Python
``eval``/``exec`` or a shell.
"""
from __future__ import annotations

import contextlib
import math
import time

import numpy as np

from ..atomic import atomic_append, atomic_write
from ..errors import (CommandError, ExpressionError, PyEvolverError, UnsupportedError,
                      did_you_mean)
from ..expr import nodes as N
from ..limits import MAX_ARRAY_ENTRIES, MAX_NESTING
# the families register their commands when imported (refused last: its
# fallbacks only take names no other family has)
from . import (constraints, eigen, element_attrs, elements, evolution, extensions, files,  # noqa: F401
               fixing, model_order, output, popping, remesh, toggles)
from . import display  # noqa: F401  (after toggles: s, show, P, geomview)
from . import refused  # noqa: F401
from . import group_guard, simplex
from . import registry, variables
from .cformat import print_value
from .nodes import ElemIndex
# re-exported: the names other modules and tests use from here
from .output import histogram_text  # noqa: F401
from .parser import command_parser, parse_command  # noqa: F401
from .split import needs_more, split_commands  # noqa: F401
from .toggles import GRAPHICS, TOGGLE_DEFAULTS, TOGGLES  # noqa: F401
from .values import (_KIND, ElemRef, Generator, Interrupted, Loaded, Proc, QRef,  # noqa: F401
                     Quit, TimeLimitExceeded, _Break, _Continue, _Return, as_float, as_int,
                     is_true)


class Env:
    """Name lookup for command expressions."""

    def __init__(self, session):
        self.session = session
        self.frames = []        # [(var name or None, ElemRef)]
        self.scopes = []        # local variables of the running commands: [dict]

    def current(self):
        return self.frames[-1][1] if self.frames else None

    def element(self, el, var):
        env = self

        class _Ctx:
            def __enter__(self_):
                env.frames.append((var, el))

            def __exit__(self_, *a):
                env.frames.pop()
        return _Ctx()

    def lookup(self, name):
        for var, el in reversed(self.frames):
            if var == name:
                return el
        s = self.session
        if self.scopes and name in self.scopes[-1]:
            return self.scopes[-1][name]
        if name in s.variables:
            return s.variables[name]
        if name in s.arrays:
            arr = s.arrays[name]
            if arr.dtype == object:
                raise ExpressionError(f"'{name}' is an array of strings; index it as {name}[i]")
            return N.array_value(arr)           # the whole array as a value
        if self.frames:
            el = self.frames[-1][1]
            try:
                return element_attrs.get_attr(s, el, name, None)
            except ExpressionError:
                pass
        return variables.internal(s, name)


# ---------------------------------------------------------------------------
# the interpreter



class Interpreter:
    """Executes parsed commands against a :class:`pyevolver.session.core.Session`."""

    def __init__(self, session):
        self.session = session
        self.env = Env(session)
        self.deadline = None        # time.monotonic() after which the command stops

    def tick(self):
        """Stop the running command when its time limit (``Session.time_limit``,
        the CLI's ``--timeout``) has passed; called once per loop pass, call,
        repetition and iteration, wherever a script could run forever."""
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise TimeLimitExceeded(f"the command ran longer than "
                                    f"{self.session.time_limit:g} s (the time limit) "
                                    f"and was stopped")

    # -- statements -----------------------------------------------------------
    def execute(self, node):
        """Run one statement: the language's own here, commands from the
        registry."""
        kind = node[0]
        run = getattr(self, "_x_" + kind, None)
        if run is not None:
            run(node)
        elif kind in simplex.STATEMENTS and self._simplex() and simplex.statement(self, node):
            return
        else:
            group_guard.check(self.session, kind, statement=True)
            registry.statement(kind).handler(self, node)

    def _simplex(self):
        """True when the surface is in the simplex model (commands.simplex)."""
        return bool(getattr(self.session.surface, "simplex", 0))

    def run_string(self, text, where):
        """Run ``text`` (any number of commands) as the Evolver's ``exec``
        does: parsed by the command parser at run time, in the global scope
        (the caller's locals and ``foreach`` elements are not visible; REF:
        ``exec "print xx"`` inside a procedure with parameter ``xx`` is a
        syntax error).  An error names ``where`` and stops the rest."""
        env = self.env
        if len(env.scopes) > MAX_NESTING:
            raise CommandError(f"{where}: exec strings run each other too deeply")
        scopes, frames = env.scopes, env.frames
        depth = len(scopes)
        env.frames = []
        try:
            for chunk, ln in split_commands(text):
                ast = parse_command(chunk, where, ln)
                scopes.append({})
                try:
                    self.execute(ast)
                finally:
                    del scopes[depth:]
        except PyEvolverError as exc:
            if str(exc).startswith(where):
                raise
            raise CommandError(f"{where}: {exc}") from None
        finally:
            env.frames = frames

    def _x_seq(self, node):
        for st in node[1]:
            self.execute(st)

    def _x_repeat(self, node):
        n = self.count(node[2])
        for _ in range(n):
            self.tick()
            self.execute(node[1])

    def count(self, expr):
        """A repetition count (an integer >= 0) from ``expr``."""
        return max(0, as_int(self.value(expr), "a repetition count"))

    def _x_if(self, node):
        if self.truth(node[1]):
            self.execute(node[2])
        elif node[3] is not None:
            self.execute(node[3])

    def _loop(self, body):
        """Run one loop body; returns False to leave the loop."""
        self.tick()
        try:
            self.execute(body)
        except _Break as b:
            if b.n > 1:
                raise _Break(b.n - 1)
            return False
        except _Continue as c:
            if c.n > 1:
                raise _Continue(c.n - 1)
        return True

    def _x_while(self, node):
        while self.truth(node[1]):
            if not self._loop(node[2]):
                break

    def _x_dowhile(self, node):
        while True:
            if not self._loop(node[1]):
                break
            if not self.truth(node[2]):
                break

    def _x_for(self, node):
        _, init, cond, step, body = node
        if init is not None:
            self.execute(init)
        while self.truth(cond):
            if not self._loop(body):
                break
            if step is not None:
                self.execute(step)

    def _x_foreach(self, node):
        # the elements are listed first (ones created by the body are not
        # visited) but, as in the Evolver, `where` is tested when each element
        # is reached, on the surface the earlier passes left
        gen, body = node[1], node[2]
        sess = self.session
        els = list(elements.gen_base(sess, gen.base, self.env))
        surf0 = sess.surface
        ids = {k: surf0.ids(k) for k in {el.kind for el in els} if k != "body"}
        hits = [0]
        try:
            self._foreach_loop(gen, body, els, surf0, ids, hits)
        finally:
            if gen.where is not None:
                sess.counts["where"] = hits[0]      # where_count: the loop's hits

    def _foreach_loop(self, gen, body, els, surf0, ids, hits):
        sess = self.session
        for el in els:
            if sess.surface is not surf0 and el.kind in ids:
                # the body changed the topology (r, delete, ...): the element is
                # found again by its id; one that was deleted is skipped
                eid = ids[el.kind][el.i]
                hit = np.nonzero(sess.surface.ids(el.kind) == eid)[0]
                if not len(hit):
                    continue
                el = ElemRef(el.kind, int(hit[0]), el.sign)
            elif el.kind == "body" and el.i >= elements.count(sess, "body"):
                continue
            with self.env.element(el, gen.var):
                if gen.where is not None:
                    v = gen.where.ev(self.env)
                    if not is_true(v):
                        continue
                    hits[0] += 1
                if not self._loop(body):
                    break

    def _x_define(self, node):
        name = node[1].lower()
        if len(node[1]) < 2:
            raise CommandError(f"'{node[1]}' is a single-letter command; redefine it with "
                               f"{node[1]} :::= {{ ... }}")
        self._check_free(name, "command")
        if name in self.session.variables:
            del self.session.variables[name]
        self.session.commands[name] = Proc(name, [], node[2])

    def _check_free(self, name, what):
        s = self.session
        if name in variables.READ_ONLY or name in s.settings or name in TOGGLES or \
                (s.surface is not None and name in s.surface.quantities):
            raise CommandError(f"'{name}' is a built-in name; it cannot be a {what}")

    def _x_procdef(self, node):
        proc = node[1]
        if len(proc.name) < 2:
            raise CommandError(f"'{proc.name}' is a single-letter command, not a "
                               f"{'function' if proc.function else 'procedure'} name")
        self._check_free(proc.name, "function" if proc.function else "procedure")
        old = self.session.commands.get(proc.name)
        if proc.body is None and old is not None and old.body is not None:
            return                      # a prototype after the definition
        self.session.variables.pop(proc.name, None)
        self.session.commands[proc.name] = proc

    def _x_redefine(self, node):
        raw, body = node[1], node[2]
        if len(raw) != 1:
            raise CommandError(f":::= redefines single-letter commands; '{raw}' is not one "
                               f"(use {raw} := {{ ... }})")
        if body is None:
            self.session.letters.pop(raw, None)
        else:
            self.session.letters[raw] = Proc(raw, [], body)

    def _x_local(self, node):
        if not self.env.scopes:
            raise CommandError("'local' is only allowed inside a command body")
        scope = self.env.scopes[-1]
        for name in node[1]:
            if len(name) < 2:
                raise CommandError(f"'{name}' is a single-letter command, not a variable")
            scope.setdefault(name, 0.0)

    def var_elem(self, name):
        """The element bound to loop variable ``name``, or None."""
        for var, el in reversed(self.env.frames):
            if var == name:
                return el
        return None

    # -- procedures -------------------------------------------------------------
    def run_proc(self, proc, args):
        """Run a user command with argument values; returns the value of
        ``return expr`` (functions) or None."""
        if proc.body is None:
            raise CommandError(f"'{proc.name}' is declared but not defined yet")
        if len(args) != len(proc.params):
            raise CommandError(f"{'function' if proc.function else 'procedure'} "
                               f"'{proc.name}' needs {len(proc.params)} argument"
                               f"{'s' if len(proc.params) != 1 else ''}, the call has "
                               f"{len(args)}")
        self.tick()
        if len(self.env.scopes) > MAX_NESTING:
            raise CommandError(f"'{proc.name}': calls nested too deep (more than {MAX_NESTING})")
        scope = {name: v for (_, name), v in zip(proc.params, args)}
        self.env.scopes.append(scope)
        try:
            self.execute(proc.body)
        except _Return as r:
            return r.value
        except (_Break, _Continue):
            return None
        finally:
            self.env.scopes.pop()
        return None

    def call_in_expr(self, name, arg_nodes):
        s = self.session
        if name == "sizeof":
            if len(arg_nodes) != 1:
                raise ExpressionError("sizeof() takes one argument")
            a = arg_nodes[0]
            if isinstance(a, N.Var) and a.name in s.arrays:
                return float(s.arrays[a.name].size)
            v = self.value(a)
            if not isinstance(v, str):
                raise ExpressionError("sizeof() needs a string or an array")
            return float(len(v))
        if name == "is_defined":
            if len(arg_nodes) != 1:
                raise ExpressionError("is_defined() takes one argument")
            v = self.value(arg_nodes[0])
            if not isinstance(v, str):
                raise ExpressionError("is_defined() needs a name in a string")
            return float(self.is_defined(v.lower()))
        if name in ("valid_constraint", "valid_boundary"):
            # 1 if the constraint / boundary (a number, or a name) is defined
            if len(arg_nodes) != 1:
                raise ExpressionError(f"{name}() takes one argument")
            v = self.value(arg_nodes[0])
            if isinstance(v, str) or not math.isfinite(float(v)):
                raise ExpressionError(f"{name}() needs a number or a name")
            table = (s.surface.constraints if name == "valid_constraint"
                     else s.surface.boundaries) if s.surface is not None else {}
            return float(float(v) == int(v) and int(v) in table)
        if name in ("new_vertex", "new_edge", "new_facet", "new_body"):
            raise UnsupportedError(f"{name}() (creating elements from a script)")
        if name == "valid_element":
            # 1 if the element exists (simply_connected.cmd: vertex[sc_startv])
            if len(arg_nodes) != 1 or not isinstance(arg_nodes[0], ElemIndex):
                raise ExpressionError("valid_element() takes one element, e.g. vertex[3]")
            try:
                arg_nodes[0].ev(self.env)
            except ExpressionError:
                return 0.0
            return 1.0
        proc = s.commands.get(name)
        if proc is None:
            raise ExpressionError(f"unknown function '{name}'")
        args = [self.value(a) for a in arg_nodes]
        v = self.run_proc(proc, args)
        if not proc.function:
            raise ExpressionError(f"'{name}' is a procedure; it has no value")
        if v is None:
            raise ExpressionError(f"function '{name}' ended without 'return value'")
        return v

    def is_defined(self, name):
        s = self.session
        if name in s.commands or name in s.variables or name in s.arrays or \
                (self.env.scopes and name in self.env.scopes[-1]):
            return True
        try:
            variables.internal(s, name)
            return True
        except PyEvolverError:
            return False

    def _x_call(self, node):
        name, args = node[1], node[2]
        proc = self.session.commands.get(name)
        if proc is None:
            if len(args) == 1 and name in ("g", "r", "u"):
                return self._x_bare(("bare", name, args[0]))
            cmd = registry.COMMANDS.get(name.lower())
            if cmd is not None and cmd.call is not None:
                return registry.call(self.session, name, [self.value(a) for a in args])
            raise CommandError(f"unknown procedure '{name}'")
        self.run_proc(proc, [self.value(a) for a in args])

    # -- arrays ----------------------------------------------------------------
    def _x_define_array(self, node):
        _, name, typ, dims = node
        s = self.session
        if len(name) < 2:
            raise CommandError(f"'{name}' is a single-letter command, not a variable")
        shape = self.sizes(dims, f"define {name}")
        if not shape:                       # `define name real`: a plain variable
            if name not in s.variables:
                variables.set_variable(s, name, "" if typ == "string" else 0.0)
            return
        if self.env.scopes and name in self.env.scopes[-1]:
            # `local vn; define vn real[3]`: the name is the array from here on
            # (pyevolver keeps arrays in one namespace)
            del self.env.scopes[-1][name]
        old = s.arrays.get(name)
        new = np.zeros(shape, dtype=object if typ == "string" else float)
        if typ == "string":
            new[...] = ""
        if old is not None and old.ndim == new.ndim and old.dtype == new.dtype:
            # redefining keeps the values (of the same type)
            sl = tuple(slice(0, min(a, b)) for a, b in zip(old.shape, new.shape))
            new[sl] = old[sl]
        s.arrays[name] = new
        s.array_types[name] = typ

    def array_slot(self, name, idx, partial=False):
        """``(array, position)`` of ``name[idx...]``; with ``partial`` fewer
        indices than dimensions name a sub-array (``evecs[2]`` of a
        ``real[20][3]``)."""
        s = self.session
        arr = s.arrays.get(name)
        if arr is None:
            raise ExpressionError(f"'{name}' is not an array (define it first: "
                                  f"define {name} real[n])")
        if len(idx) != arr.ndim and not (partial and 0 < len(idx) < arr.ndim):
            raise ExpressionError(f"array '{name}' has {arr.ndim} dimension"
                                  f"{'s' if arr.ndim != 1 else ''}, got {len(idx)} indices")
        pos = []
        for k, n in zip(idx, arr.shape):
            k = as_int(k, f"an index of array '{name}'")
            if k < 1 or k > n:
                raise ExpressionError(f"array '{name}': index {k} is outside 1..{n}")
            pos.append(k - 1)
        return arr, tuple(pos)

    def sizes(self, dims, what, per=1):
        """Array sizes from ``dims`` expressions: integers >= 0 whose product
        (times ``per`` elements) stays within :data:`~pyevolver.limits.MAX_ARRAY_ENTRIES`."""
        shape = []
        total = per
        for d in dims:
            v = self.value(d)
            if isinstance(v, str) or not (0 <= v < float("inf")):
                raise CommandError(f"{what}: array sizes must be numbers >= 0")
            shape.append(int(v))
            total *= int(v)
        # (real[0][huge] and real[huge][0] have no entries, but numpy
        # cannot make the huge dimension)
        total = max([total] + shape)
        if total > MAX_ARRAY_ENTRIES:
            raise CommandError(f"{what}: {total} entries is more than the "
                               f"{MAX_ARRAY_ENTRIES} allowed")
        return shape

    def _x_assign(self, node):
        self._store(node[1], self.value(node[2]))

    def _x_opassign(self, node):
        lv, op, expr = node[1], node[2], node[3]
        old = self._load(lv)
        v = self.value(expr)
        if isinstance(old, str) or isinstance(v, str):
            raise CommandError(f"'{op}=' needs numbers")
        if op == "/" and not isinstance(v, np.ndarray) and v == 0:
            raise ExpressionError("Division by zero.")
        if op == "*" and isinstance(old, N.ArrayValue) and isinstance(v, N.ArrayValue):
            raise CommandError("'*=' of two arrays: use a := a * b for the dot product")
        new = {"+": lambda: old + v, "-": lambda: old - v, "*": lambda: old * v,
               "/": lambda: old / v}[op]()
        self._store(lv, new)

    def _load(self, lv):
        if lv[0] == "name":
            return self.env.lookup(lv[1].lower())
        if lv[0] == "array":
            arr, pos = self.array_slot(lv[1], [self.value(i) for i in lv[2]], partial=True)
            v = arr[pos]
            return N.array_value(v) if np.ndim(v) else v
        base = lv[1].ev(self.env)
        return element_attrs.get_attr(self.session, base, lv[2], self._index(lv[3]))

    def _store(self, lv, value):
        s = self.session
        if lv[0] == "name":
            name = lv[1].lower()
            if len(lv[1]) < 2:
                raise CommandError(f"'{lv[1]}' is a single-letter command, not a variable "
                                   f"(variable names need two or more characters)")
            for var, el in self.env.frames:
                if var == name:
                    raise CommandError(f"cannot assign to loop variable '{name}'")
            if self.env.scopes and name in self.env.scopes[-1]:
                self.env.scopes[-1][name] = value
                return
            if name in s.commands:
                del s.commands[name]
            if name in s.arrays:
                self._fill(name, s.arrays[name], (), value)
                return
            if isinstance(value, N.ArrayValue):
                raise CommandError(f"'{name}' is not an array; define it first "
                                   f"(define {name} real" +
                                   "".join(f"[{n}]" for n in value.shape) + ")")
            variables.set_variable(s, name, value)
            return
        if lv[0] == "array":
            arr, pos = self.array_slot(lv[1], [self.value(i) for i in lv[2]], partial=True)
            if len(pos) < arr.ndim:
                self._fill(lv[1], arr, pos, value)
            elif isinstance(value, N.ArrayValue):
                raise CommandError(f"{lv[1]}[...]: an array does not fit in one entry")
            elif arr.dtype == object:
                arr[pos] = value if isinstance(value, str) else print_value(value).strip()
            elif isinstance(value, str):
                raise CommandError(f"array '{lv[1]}' holds numbers, not strings")
            else:
                arr[pos] = value
            return
        base = lv[1].ev(self.env)
        s.set_attr(base, lv[2], self._index(lv[3]), value)

    @staticmethod
    def _fill(name, arr, pos, value):
        """Assign a number (to every entry) or an array of the same shape to
        the (sub-)array ``arr[pos]``."""
        if isinstance(value, str) or arr.dtype == object:
            raise CommandError(f"array '{name}': whole-array assignment needs numbers")
        target = arr[pos] if pos else arr
        if isinstance(value, N.ArrayValue) and value.shape != target.shape:
            raise CommandError(f"array '{name}': cannot assign shape {list(value.shape)} "
                               f"to shape {list(target.shape)}")
        if pos:
            arr[pos] = np.asarray(value)
        else:
            arr[...] = np.asarray(value)

    def _index(self, idx):
        if idx is None:
            return None
        if isinstance(idx, list):
            return tuple(self.value(i) for i in idx)
        return self.value(idx)

    def _x_assign_array(self, node):
        lv, items = node[1], node[2]
        if lv[0] != "name":
            raise CommandError("a {...} list can only be assigned to an array name")
        name = lv[1].lower()

        def shape(x):
            return [len(x)] + shape(x[0]) if isinstance(x, list) else []

        def flat(x):
            if isinstance(x, list):
                return [v for it in x for v in flat(it)]
            return [as_float(self.value(x), f"a value of array {name}")]
        vals = flat(items)
        s = self.session
        arr = s.arrays.get(name)
        if arr is None:
            dims = "".join(f"[{n}]" for n in shape(items))
            raise CommandError(f"'{name}' is not an array; define it first "
                               f"(define {name} real{dims})")
        if arr.dtype == object:
            raise CommandError(f"array '{name}' holds strings")
        flat_arr = arr.reshape(-1)
        if len(vals) > flat_arr.size:
            raise CommandError(f"array '{name}' has {flat_arr.size} entries; the list has "
                               f"{len(vals)}")
        flat_arr[:len(vals)] = vals

    def _x_redirect(self, node):
        _, body, op, target = node
        name = self.value(target)
        if not isinstance(name, str) or not name:
            raise CommandError(f"'{op}' needs a file name in quotes (for example: "
                               f"do_off {op} \"out.off\")")
        s = self.session
        # the file changes only when the command completes (atomic_write): a
        # failing or interrupted command leaves it as it was
        with contextlib.ExitStack() as stack:
            try:
                fh = stack.enter_context(
                    atomic_write(name, "w", durable=False, encoding="latin-1", newline="")
                    if op == ">>>" else atomic_append(name, encoding="latin-1", newline=""))
            except OSError as exc:
                raise CommandError(f"cannot open '{name}' for output: "
                                   f"{exc.strerror or exc}") from None
            old = s.out
            s.out = fh
            flow = None
            try:
                self.execute(body)
            except (_Break, _Continue, _Return, Loaded, Quit) as exc:
                flow = exc              # normal control flow: the output is kept
            finally:
                s.out = old
        if flow is not None:
            raise flow

    def _x_pipe(self, node):
        raise UnsupportedError("piping output to a command ('|')",
                               "scripts never reach a shell; use >> or >>> to write a file")

    def _x_break(self, node):
        raise _Break(1 if node[1] is None else as_int(self.value(node[1]), "break's count"))

    def _x_continue(self, node):
        raise _Continue(1 if node[1] is None else as_int(self.value(node[1]),
                                                         "continue's count"))

    def _x_return(self, node):
        raise _Return(None if node[1] is None else self.value(node[1]))

    def _x_bare(self, node):
        raw, arg = node[1], node[2]
        name = raw.lower()
        s = self.session
        builtin = len(node) > 3
        if name in s.commands and len(raw) > 1:
            proc = s.commands[name]
            if proc.params:
                if arg is None:
                    raise CommandError(f"'{raw}' needs {len(proc.params)} argument"
                                       f"{'s' if len(proc.params) != 1 else ''}: "
                                       f"{raw}(...)")
                self.run_proc(proc, [self.value(arg)])
                return
            n = 1 if arg is None else self.count(arg)
            for _ in range(n):
                self.tick()
                self.run_proc(proc, [])
            return
        if not builtin and raw in s.letters:
            n = 1 if arg is None else self.count(arg)
            for _ in range(n):
                self.tick()
                self.run_proc(s.letters[raw], [])
            return
        cmd = registry.lookup(raw, arg)
        if cmd is not None:
            if self._simplex() and simplex.answer(self, raw):
                return
            group_guard.check(self.session, raw)
            cmd.handler(self, raw, arg)
            return
        if name in s.variables and arg is None:
            raise CommandError(f"'{raw}' is a variable, not a command (use print {raw})")
        names = [w for w in registry.words() if len(w) > 1] + list(s.commands)
        raise CommandError(f"unknown command '{raw}'" + did_you_mean(name, names))

    # -- expressions ------------------------------------------------------------
    def value(self, expr):
        v = expr.ev(self.env)
        if isinstance(v, N.ArrayValue):
            return v
        if isinstance(v, np.ndarray):
            if v.size != 1:
                raise CommandError(f"expected a number here, got an array of shape "
                                   f"{list(v.shape)}")
            v = float(v.reshape(()))
        if isinstance(v, (ElemRef, QRef)):
            raise CommandError("an element or quantity is not a value here")
        return v

    def truth(self, expr):
        v = self.value(expr)
        if isinstance(v, str):
            return bool(v)
        if isinstance(v, np.ndarray):
            raise ExpressionError(f"a condition must be a number, got {N._what(v)}")
        return v != 0
