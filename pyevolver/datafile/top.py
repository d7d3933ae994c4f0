"""The top section of a datafile: declarations -> :class:`Scene` fields.

A mixin of :class:`pyevolver.datafile.reader.Reader` (which provides
``scene``, ``error``, ``_src``, ``_const``, ``_formula``, ``_value``): the
procedures cut out, the PERIODS / VIEW_* matrices taken out, the rest parsed
by ``fe_top.lark`` and each declaration filled into the scene.
"""
from __future__ import annotations

import math
import re

import numpy as np
from lark.exceptions import UnexpectedInput, VisitError

from ..errors import PyEvolverError
from ..expr import nodes as N
from ..limits import MAX_ARRAY_ENTRIES, MAX_NESTING, nesting_depth
from ..model.scene import BoundaryDecl, ConstraintDecl, MethodDecl, QuantityDecl
from ..model.metric import Metric, metric_orders_refusal
from .grammar import _LINE, _TOP, line_parser, top_parser
from .located import _LocatedName, _MatrixError, _Unsupported
from .scan import (_ARRAY_TOKEN, _ATTR_FUNCTION, _BAD_NUMBER, _INT_ATTR_TYPES, _MATRIX_RE,
                   _NUMTOK_RE, _PROC_START, _SPACE_DIM_RE, _lowest_free, _proc_end,
                   _skip_transforms)

_SYMMETRY_RE = re.compile(r'\bsymmetry_group\s+"([^"\n]*)"', re.I)

VALUE_NAMES = {
    "square_curvature": "squared_curvature",
    "spring_constant": "gap_constant",
    "integral_order": "integral_order",
}


class TopSection:
    """Reading the top section (mixin of the reader)."""

    def _matrix_exprs(self, text, m, count):
        """The ``count`` values after the PERIODS or VIEW_MATRIX keyword ``m``:
        expressions separated by white space as on an element line (manual:
        "PERIODS followed by expressions"; ``1 -2`` is two values, ``1 - 2``
        one), whole lines at a time.  Returns ``(exprs, end)``."""
        pos = m.end()
        vals = []
        while len(vals) < count and pos < len(text):
            nl = text.find("\n", pos)
            nl = len(text) if nl < 0 else nl
            seg = text[pos:nl]
            if seg.strip():
                try:
                    tree = line_parser().parse("0 " + seg, start="vertex_line")
                    _, items = _LINE.transform(tree)
                except (UnexpectedInput, VisitError):
                    break
                if any(isinstance(it, tuple) for it in items):
                    break
                vals.extend(items)
            pos = nl + 1 if nl < len(text) else nl
        return vals, min(pos, len(text))

    def _extract_matrices(self, text):
        """Take the numbers of PERIODS / VIEW_* matrices out of the text."""
        out = text
        for m in _MATRIX_RE.finditer(text):
            key = m.group(1).lower()
            if key.endswith("periods") or key == "view_matrix":
                # rows given by expressions (parameters, arithmetic) or numbers
                sd = self._peek_space_dimension(text[:m.start()])
                count = sd * sd if key.endswith("periods") else (sd + 1) ** 2
                vals, pos = self._matrix_exprs(text, m, count)
                line = text.count("\n", 0, m.start()) + 1
                if len(vals) != count:
                    raise _MatrixError(line, f"{key.upper()} needs {count} numbers, "
                                             f"found {len(vals)}")
                out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
                if key.endswith("periods"):
                    self._period_exprs = vals
                continue
            if key == "metric":             # N² component formulas, any line layout
                sd = self._peek_space_dimension(text[:m.start()])
                vals, pos = self._matrix_exprs(text, m, sd * sd)
                if len(vals) != sd * sd:
                    line = text.count("\n", 0, m.start()) + 1
                    raise _MatrixError(line, f"METRIC needs {sd * sd} components, "
                                             f"found {len(vals)}")
                out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
                self._metric_exprs = vals
                continue
            pos = m.end()
            if key.startswith("view_transform"):
                # n, then n matrices, each after an optional COLOR c or SWAP_COLORS
                pos = _skip_transforms(text, pos, self._peek_space_dimension(text[:m.start()]))
                out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
                continue
            vals = []
            limit = None
            if m.group(1).lower().endswith("periods"):
                sd = self._peek_space_dimension(text[:m.start()])
                limit = sd * sd
            while limit is None or len(vals) < limit:
                mm = _NUMTOK_RE.match(text, pos)
                if not mm:
                    break
                vals.append(float(mm.group(1).replace("d", "e").replace("D", "e")))
                pos = mm.end()
            out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
            if limit is not None:
                if len(vals) != limit:
                    line = text.count("\n", 0, m.start()) + 1
                    raise _MatrixError(line, f"PERIODS needs {limit} numbers, found {len(vals)}")
                if not all(math.isfinite(v) for v in vals):
                    line = text.count("\n", 0, m.start()) + 1
                    raise _MatrixError(line, "PERIODS: the numbers must be finite")
                self.scene.values["_periods"] = vals
        return out

    def _symmetry_group(self, text, sec):
        """``SYMMETRY_GROUP "name"`` taken out of the text into
        ``scene.symmetry_group`` (the builder checks the name:
        :mod:`pyevolver.model.symmetry`)."""
        m = _SYMMETRY_RE.search(text)
        if not m:
            return text
        self.scene.symmetry_group = m.group(1).lower()
        self.scene.decl_lines["symmetry_group"] = self._src(sec, text.count("\n", 0, m.start()) + 1)
        return text[:m.start()] + " " * (m.end() - m.start()) + text[m.end():]

    def _peek_space_dimension(self, text):
        m = re.search(r"\bspace_dimension\s+(\d+)", text, re.I)
        return int(m.group(1)) if m else 3

    def _cut_procedures(self, sec):
        """Take the stand-alone ``procedure`` and ``function`` declarations and
        definitions out of the top section (manual, "Functions and
        procedures": the read-section syntax, allowed in the top section).

        They are kept, with their source lines, in ``scene.top_commands`` (run
        as commands before the read section) and blanked in the text, so the
        line and column of everything else are kept.
        """
        text = sec.text
        self._functions = set()
        self._procedures = set()
        af = _ATTR_FUNCTION.search(text)
        if af:
            line = text.count("\n", 0, af.start(1)) + 1
            raise self.error("not supported in pyevolver: attribute FUNCTION (an extra "
                             "attribute computed by a procedure)", self._src(sec, line),
                             af.start(1) - text.rfind("\n", 0, af.start(1)))
        if not _PROC_START.search(text):
            return text
        out = []
        pos = 0
        for m in _PROC_START.finditer(text):
            if m.start() < pos:
                continue
            end = _proc_end(text, m.end() - 1)
            line = text.count("\n", 0, m.start()) + 1
            if end is None:
                raise self.error(f"unbalanced parentheses or braces in this "
                                 f"{m.group(1).lower()} declaration", self._src(sec, line),
                                 m.start() - text.rfind("\n", 0, m.start()))
            body = text[m.start():end]
            self.scene.top_commands.append((body.rstrip().rstrip(";"), self._src(sec, line)))
            if m.group(1).lower() == "procedure":
                self._procedures.add(re.match(r"\w+\s+(\w+)", body).group(1).lower())
            if m.group(1).lower() == "function":
                self._functions.add(re.match(r"\w+\s+(?:\w+\s+)?(\w+)", body).group(1).lower())
            out.append(text[pos:m.start()])
            out.append(re.sub(r"[^\n]", " ", body))
            pos = end
        out.append(text[pos:])
        text = "".join(out)
        if self._functions:
            # a user function called in a top-section expression (REF evaluates
            # it with its command interpreter; pyevolver's datafile reader has none)
            call = re.search(r"\b(" + "|".join(map(re.escape, sorted(self._functions))) +
                             r")\s*\(", text, re.I)
            if call:
                line = text.count("\n", 0, call.start()) + 1
                raise self.error(f"not supported in pyevolver: calling the user function "
                                 f"{call.group(1)} in the top section of a datafile",
                                 self._src(sec, line),
                                 call.start() - text.rfind("\n", 0, call.start()))
        return text

    def _top(self, sec):
        if _PROC_START.search(sec.text) or _ATTR_FUNCTION.search(sec.text):
            sec.text = self._cut_procedures(sec)
        text = sec.text.replace(",", " ")
        bad = _BAD_NUMBER.search(text)
        if bad:
            line = text.count("\n", 0, bad.start()) + 1
            col = bad.start() - (text.rfind("\n", 0, bad.start()) + 1) + 1
            raise self.error(f"malformed number '{bad.group(0)}'", self._src(sec, line), col)
        sdm = _SPACE_DIM_RE.search(text)
        if sdm and int(sdm.group(1)) > 3 and re.search(r"^[ \t]*string\b", text, re.I | re.M):
            # a string model above 3 dimensions is refused whatever else the
            # file says: say so before parsing the rest (the soapfilm model
            # runs in 4 to 9 dimensions: pyevolver.methods.ndim)
            line = text.count("\n", 0, sdm.start()) + 1
            raise self.error(f"not supported in pyevolver: SPACE_DIMENSION {sdm.group(1)} "
                             f"(3, or 2 in the string model)", self._src(sec, line),
                             sdm.start() - (text.rfind("\n", 0, sdm.start()) + 1) + 1)
        fdef = _ATTR_FUNCTION.search(text)
        if fdef:
            line = text.count("\n", 0, fdef.start(1)) + 1
            col = fdef.start(1) - (text.rfind("\n", 0, fdef.start(1)) + 1) + 1
            raise self.error("not supported in pyevolver: DEFINE ... ATTRIBUTE ... FUNCTION "
                             "(attributes computed when read)", self._src(sec, line), col)
        text = self._symmetry_group(text, sec)
        try:
            if _MATRIX_RE.search(text):
                text = self._extract_matrices(text)
            if text.strip(" \t\f\r\n"):     # (the grammar's blanks; else no declaration)
                decls = _TOP.transform(top_parser().parse(text, start="start"))
            else:
                decls = []      # (start-up: a top section of comments needs no parser)
        except _MatrixError as exc:
            raise self.error(exc.args[1], self._src(sec, exc.args[0]), 1) from None
        except _Unsupported as exc:
            kw = exc.args[0]
            raise self.error(f"not supported in pyevolver: {str(kw).upper()}",
                             self._src(sec, kw.line), kw.column) from None
        except UnexpectedInput as exc:
            line = exc.line if exc.line not in (None, -1) else 1
            srcline = sec.lines[line - 1] if sec.lines else line
            raise self.error(self._describe(exc, text), srcline,
                             exc.column if exc.column not in (None, -1) else None) from None
        except VisitError as exc:
            orig = exc.orig_exc
            if isinstance(orig, _Unsupported):
                kw = orig.args[0]
                srcline = sec.lines[kw.line - 1] if sec.lines else kw.line
                raise self.error(f"not supported in pyevolver: {str(kw).upper()}",
                                 srcline, kw.column) from None
            if isinstance(orig, PyEvolverError):
                line = getattr(orig, "line", None)
                raise self.error(str(orig), self._src(sec, line) if line else sec.line,
                                 getattr(orig, "column", None)) from None
            raise
        for d in decls:
            if nesting_depth(d) > MAX_NESTING:
                line = d[-1] if isinstance(d[-1], int) else 1
                raise self.error(f"expression nested more than {MAX_NESTING} levels deep",
                                 self._src(sec, line))
        self._fill_scene(decls, sec)


    def _fill_scene(self, decls, sec):
        sc = self.scene
        self._forward = {}
        self._orders = []
        for d in decls:
            kind = d[0]
            try:
                self._decl(d, sc, sec)
            except _LocatedName as exc:
                raise self.error(f"undefined parameter '{exc.name}'",
                                 self._src(sec, exc.line) if exc.line else None,
                                 exc.col) from None
        if self._orders:
            why = metric_orders_refusal(sc)
            if why is not None:
                msg, line = self._orders[0]
                raise self.error(msg + (f"; {why}" if why else ""), line)
        for name, (kind, line) in self._forward.items():
            known = sc.quantities if kind == "quantity_forward" else sc.method_instances
            if name not in known:
                what = "quantity" if kind == "quantity_forward" else "method_instance"
                raise self.error(f"{what} {name} is declared but never defined", line)

    def _decl(self, d, sc, sec):
        kind = d[0]
        if kind == "parameter":
            _, name, expr, line = d[:4]
            if len(d) > 4:
                self._parameter_options(name, d[4], self._src(sec, line))
            if isinstance(expr, N.Str):         # a string-valued parameter
                sc.parameters[name] = expr.value
                return
            sc.parameters[name] = self._const(expr, self._src(sec, line), f"parameter {name}")
        elif kind == "flag":
            sc.flags.add(d[1])
            sc.decl_lines[d[1]] = self._src(sec, d[2])
        elif kind == "value":
            _, name, expr, fixed, line = d
            name = VALUE_NAMES.get(name, name)
            sc.values[name] = self._const(expr, self._src(sec, line), name)
            sc.decl_lines[name] = self._src(sec, line)
            if name in ("space_dimension", "surface_dimension") and \
                    sc.values[name] not in ((1, 2, 3, 4, 5, 6, 7, 8, 9)
                                            if name == "space_dimension" else (1, 2, 3, 4)):
                raise self.error(f"not supported in pyevolver: {name.upper()} "
                                 f"{sc.values[name]:g}", self._src(sec, line))
            if fixed:
                sc.values[name + "_fixed"] = 1.0
            if name.startswith("integral_order") and not abs(sc.values[name]) <= 1e6:
                raise self.error(f"{name.upper()} {sc.values[name]:g} is out of range "
                                 f"(a quadrature order)", self._src(sec, line))
            # the quadrature orders: pyevolver has REF's default rules only
            default = {"integral_order_1d": 3.0, "integral_order_2d": 6.0}.get(name)
            if "quadratic" in sc.flags:     # REF's dump of the quadratic model writes 5 and 3
                default = {"integral_order_1d": 5.0, "integral_order_2d": 3.0}.get(name)
            if name == "integral_order" or (default is not None and
                                            sc.values[name] != default):
                # refused at the end of the top section unless a metric uses it
                # (pyevolver.methods.metric has REF's rules for the metric's integrals)
                self._orders.append((f"not supported in pyevolver: {name.upper()} "
                                     f"{sc.values[name]:g} (edge integrals use order 3 and facet "
                                     f"integrals order 6, the Evolver's defaults)",
                                     self._src(sec, line)))
                if name == "integral_order":    # REF: INTEGRAL_ORDER n is 2D n and 1D 2n - 1
                    sc.values["integral_order_2d"] = sc.values[name]
                    sc.values["integral_order_1d"] = 2 * sc.values[name] - 1
        elif kind == "constraint":
            _, cid, opts, formula, blocks, line = d
            cid = self._number_named(cid, sc.constraints, sc.constraint_names, "constraint",
                                     self._src(sec, line))
            if cid in sc.constraints:
                raise self.error(f"constraint {cid} defined twice", self._src(sec, line))
            for o in [o for o in opts if isinstance(o, tuple)]:
                # the content integral's side with several content constraints
                self._defer("CONTENT_RANK", self._src(sec, o[2]), o[3])
                opts.remove(o)
            c = ConstraintDecl(cid, self._formula(formula), set(opts), line=self._src(sec, line))
            for bname, comps in blocks:
                setattr(c, bname, self._components(comps, "ec"[bname == "content"], sec, line))
            sc.constraints[cid] = c
        elif kind == "boundary":
            _, bid, npar, opts, comps, blocks, line = d
            bid = self._number_named(bid, sc.boundaries, sc.boundary_names, "boundary",
                                     self._src(sec, line))
            if bid in sc.boundaries:
                raise self.error(f"boundary {bid} defined twice", self._src(sec, line))
            if not 1 <= npar <= 3:
                raise self.error(f"boundary {bid}: PARAMETERS must be 1, 2 or 3, got {npar}",
                                 self._src(sec, line))
            # a boundary's coordinates are functions of its parameters only
            coords = self._components(comps, "x", sec, line,
                                      allowed=tuple(f"p{k + 1}" for k in range(npar)))
            b = BoundaryDecl(bid, npar, coords, set(opts), line=self._src(sec, line))
            for bname, bcomps in blocks:
                setattr(b, bname, self._components(bcomps, "ec"[bname == "content"], sec, line))
            sc.boundaries[bid] = b
        elif kind == "quantity":
            _, name, kindt, rest, line = d
            q = QuantityDecl(name, kindt[1], line=self._src(sec, line))
            if kindt[2] is not None:
                q.target = self._const(kindt[2], q.line, f"quantity {name} target")
            for r in rest:
                if r[0] in ("modulus", "tolerance", "lagrange_multiplier"):
                    setattr(q, r[0], self._const(r[1], q.line, f"quantity {name} {r[0]}"))
                elif r[0] == "method":
                    q.methods.append(self._method(r[1], r[2], r[3], sec, line, name))
                elif r[0] == "function":
                    q.function = r[1]
            sc.quantities[name] = q
        elif kind == "method_instance":
            _, name, mname, opts, line = d
            m = self._method(mname, False, opts, sec, line, name)
            m.line = self._src(sec, line)
            sc.method_instances[name] = m
        elif kind == "attribute":
            _, etype, name, atype, dims, line = d
            dims = [self._dim(e, self._src(sec, line), name) for e in dims]
            if atype in _INT_ATTR_TYPES:
                atype = "integer"        # the Evolver's integer types; stored as numbers
            elif atype != "real":
                raise self.error(f"not supported in pyevolver: {atype.upper()} element "
                                 f"attributes (attribute {name})", self._src(sec, line))
            size = math.prod(dims) if dims else 1
            if size > MAX_ARRAY_ENTRIES:
                raise self.error(f"attribute {name}: {size} entries per {etype}; at most "
                                 f"{MAX_ARRAY_ENTRIES} are allowed", self._src(sec, line))
            sc.attributes[(etype, name)] = (atype, size, dims)
        elif kind == "forward":          # constraint NAME;  boundary NAME;
            _, what, name, line = d
            table, names = ((sc.constraints, sc.constraint_names) if what == "constraint"
                            else (sc.boundaries, sc.boundary_names))
            if name not in names.values():
                self._number_named(name, table, names, what, self._src(sec, line))
                self._named_forward.add((what, name))
        elif kind == "global_array":
            self._global_array(d, sc, sec)
        elif kind in ("quantity_forward", "instance_forward"):
            # ``quantity name;``, ``method_instance name;``: declared now, defined
            # later in the top section
            self._forward.setdefault(d[1], (kind, self._src(sec, d[2])))
        elif kind == "periods":
            exprs = getattr(self, "_period_exprs", None)
            if exprs is not None:       # expressions: evaluated here, in order
                line = self._src(sec, d[2])
                if any(nesting_depth(e) > MAX_NESTING for e in exprs):
                    raise self.error(f"expression nested more than {MAX_NESTING} levels deep",
                                     line)
                vals = [self._value(e, line, "PERIODS") for e in exprs]
                if not all(math.isfinite(v) for v in vals):
                    raise self.error("PERIODS: the values must be finite", line)
                sc.values["_periods"] = vals
                if any(not isinstance(e, (float, N.Num)) for e in exprs):
                    sc.values["_period_exprs"] = exprs
            # (plain numbers were taken by _extract_matrices)
        elif kind == "metric":
            self._metric_decl(d, sc, sec)
        elif kind == "ignored":
            pass

    def _metric_decl(self, d, sc, sec):
        """METRIC / CONFORMAL_METRIC / KLEIN_METRIC -> ``sc.values["_metric"]``
        (a :class:`pyevolver.model.metric.Metric`; orders filled in by the builder)."""
        _, kind, exprs, line = d
        if kind == "matrix":
            exprs = getattr(self, "_metric_exprs", [])
        if "_metric" in sc.values:
            raise self.error("a second metric declaration", self._src(sec, line))
        if any(nesting_depth(e) > MAX_NESTING for e in exprs):
            raise self.error(f"expression nested more than {MAX_NESTING} levels deep",
                             self._src(sec, line))
        comps = [self._formula(e if not isinstance(e, float) else N.Num(e)) for e in exprs]
        sc.values["_metric"] = Metric(kind, comps, sc.space_dimension, line=self._src(sec, line))

    def _defer(self, feature, line, col=None):
        """An unsupported feature met while reading: the file is read to the
        end, then refused by name at the first such feature (located)."""
        self.scene.unsupported.append((feature, line, col))

    def _parameter_options(self, name, opts, line):
        """OPTIMIZING_PARAMETER (``g`` moves it with the vertices:
        :mod:`pyevolver.evolve.optparams`), PDELTA / PSCALE (its finite
        difference and motion scale, defaults 0.0001 and 1; kept for plain
        parameters too), ON_ASSIGN_CALL."""
        vals = {"pdelta": 1e-4, "pscale": 1.0}
        for key in ("pdelta", "pscale"):
            if key in opts:
                vals[key] = self._const(opts[key][0], line, f"{key} of parameter {name}")
        if opts.get("optimizing"):
            self.scene.optimizing[name] = (vals["pdelta"], vals["pscale"])
        elif "pdelta" in opts or "pscale" in opts:
            self.scene.param_deltas[name] = (vals["pdelta"], vals["pscale"])
        if "on_assign_call" in opts:
            # the procedure runs whenever the variable is assigned (manual); it
            # must have been declared before, in the top section
            proc, col = opts["on_assign_call"]
            if proc not in getattr(self, "_procedures", ()):
                raise self.error(f"ON_ASSIGN_CALL: '{proc}' is not a procedure declared "
                                 f"above (e.g. procedure {proc}();)", line, col)
            self.scene.on_assign[name] = proc

    def _dim(self, expr, line, name):
        """An attribute's array dimension: a constant expression (REF:
        ``real[nn+1]``), a positive integer."""
        v = self._const(expr, line, f"the dimension of attribute {name}")
        if not (math.isfinite(v) and v == int(v) and v >= 0):
            raise self.error(f"attribute {name}: the dimension must be a non-negative "
                             f"integer, got {v:g}", line)
        return int(v)

    def _number_named(self, key, table, names, what, line):
        """The number of a constraint or boundary declared by number or by name.

        A name takes the lowest number not in use; a later declaration by a
        number a name holds moves the name to the lowest free number (REF:
        ``constraint aa``, ``constraint bb``, ``constraint 1`` give aa 3, bb 2).
        """
        if isinstance(key, int):
            if key in names:
                name = names.pop(key)
                decl = table.pop(key, None)     # (None: only declared ahead so far)
                new = _lowest_free(table, names, also=key)
                if decl is not None:
                    decl.id = new
                    table[new] = decl
                names[new] = name
            return key
        if key in names.values():
            if (what, key) in self._named_forward:     # declared ahead, defined now
                self._named_forward.discard((what, key))
                return next(c for c, n in names.items() if n == key)
            raise self.error(f"{what} '{key}' defined twice", line)
        if key in self.scene.parameters:
            raise self.error(f"{what} name '{key}' is already a parameter", line)
        new = _lowest_free(table, names)
        names[new] = key
        return new

    def _global_array(self, d, sc, sec):
        _, name, atype, dims, init, line, iline = d
        where = self._src(sec, line)
        dims = [self._dim(e, where, name) for e in dims]
        if atype not in ("real", "string") and atype not in _INT_ATTR_TYPES:
            raise self.error(f"not supported in pyevolver: {atype.upper()} arrays "
                             f"(array {name})", where)
        size = math.prod(dims) if dims else 1
        if size > MAX_ARRAY_ENTRIES:
            raise self.error(f"array {name}: {size} entries; at most {MAX_ARRAY_ENTRIES} are "
                             f"allowed", where)
        # the values in braces, row by row: numbers or strings
        depth, shape_ok, vals = 0, True, []
        for m in _ARRAY_TOKEN.finditer(init):
            tok = m.group(0)
            if tok == "{":
                depth += 1
                shape_ok = shape_ok and depth <= len(dims)
            elif tok == "}":
                depth -= 1
            elif tok.startswith('"'):
                vals.append(tok[1:-1].encode("latin-1").decode("unicode_escape"))
            else:
                vals.append(float(tok.replace("d", "e").replace("D", "e")))
        strings = atype == "string"
        if not shape_ok or len(vals) != size or any(isinstance(v, str) != strings
                                                     for v in vals):
            raise self.error(f"array {name}: expected {size} "
                             f"{'strings' if strings else 'numbers'} in "
                             f"{len(dims)} levels of braces for {atype}"
                             + "".join(f"[{k}]" for k in dims), self._src(sec, iline))
        arr = np.array(vals, dtype=object if strings else float).reshape(dims)
        sc.arrays[name] = ("integer" if atype in _INT_ATTR_TYPES else atype, arr)

    def _method(self, mname, is_global, opts, sec, line, qname):
        m = MethodDecl(mname, is_global, name=qname)
        for o in opts:
            if o[0] == "global":
                m.is_global = True
            elif o[0] == "scalar":
                m.scalar = self._formula(o[1])
            elif o[0] == "vector":
                m.vector = self._components(o[1], "q", sec, line)
            elif o[0] == "modulus":
                m.modulus = self._const(o[1], self._src(sec, line), "modulus")
            elif o[0] == "parameter_1":
                m.parameter_1 = self._const(o[1], self._src(sec, line), "parameter_1")
            elif o[0] == "ignore_fixed":
                m.ignore_fixed = True
            elif o[0] == "ignore_constraints":
                m.ignore_constraints = True
        return m

    def _components(self, comps, letter, sec, line, allowed=None):
        out = {}
        for key, expr in comps:
            if key[0] != letter:
                raise self.error(f"unexpected component '{key.upper()}': expected "
                                 f"{letter.upper()}1, {letter.upper()}2, ...",
                                 self._src(sec, line))
            out[int(key[1:])] = self._formula(expr, allowed=allowed)
        n = max(out) if out else 0
        return [out.get(i + 1, N.Formula(N.Num(0.0))) for i in range(n)]
