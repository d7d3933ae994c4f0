"""The element sections of a datafile: vertices, edges, faces, bodies.

A mixin of :class:`pyevolver.datafile.reader.Reader` (which provides
``scene``, ``error``, ``warn``, ``_value``, ``_named_ids``): lines of plain
numbers are converted in bulk with numpy, the others parsed by
``fe_elements.lark``; each element's values and attributes are checked and
stored in the scene's blocks.
"""
from __future__ import annotations

import math
import re
from array import array

import numpy as np
from lark.exceptions import UnexpectedInput, VisitError

from ..errors import PyEvolverError, did_you_mean
from ..expr import nodes as N
from ..limits import MAX_FACE_EDGES, MAX_ID, MAX_NESTING, nesting_depth
from .grammar import _LINE, line_parser
from .located import _LocatedName, _keywords
from .table import floats_of, numeric_table
from .scan import (_BAD_NUMBER, _KW_INTEGER, _KW_NEEDS_VALUE, _LONG, _NUMERIC_HEAD,
                   _NUMERIC_LINE, _binary_minus_in_parens, _long_numeric, _plain_tail)


class ElementSections:
    """Reading the element sections (mixin of the reader)."""

    def _elements(self, sec):
        """Parse one element section.

        Lines of plain numbers are converted in bulk with numpy; a line whose
        numbers are followed by attributes sends only the attributes to the
        grammar; anything else is parsed whole by ``fe_elements.lark``.
        """
        kind = sec.kind
        block = getattr(self.scene, kind)
        if not len(block.ids):
            table = numeric_table(sec.text, sec.line, sec.lines, _LONG)
            if table is not None:               # a plain table: read at once (datafile.table)
                vals, lens, src = table
                block.lines = array("i", src.astype("i").tobytes())    # (4 bytes: memory)
                self._bulk_values(kind, block, range(len(lens)), vals, lens, whole=True)
                return
        start = {"vertices": "vertex_line", "edges": "edge_line", "faces": "face_line",
                 "bodies": "body_line"}[kind]
        lines = sec.text.split("\n")
        torus = self.scene.torus
        sdim = self.scene.space_dimension
        nums = _NUMERIC_LINE.match
        head_re = _NUMERIC_HEAD.match
        numeric_pos = []       # positions in the block of pure numeric lines
        numeric_txt = []
        entries = 0
        for k, raw in enumerate(lines):
            if not raw or raw.isspace():
                continue
            srcline = sec.lines[k] if sec.lines else sec.line + k
            long_kind = long_head = None
            if len(raw) > _LONG:
                long_kind, long_head = _long_numeric(raw.replace(",", " ").replace(":", " "))
            if long_kind == "all" or (long_kind is None and len(raw) <= _LONG and nums(raw)):
                block.ids.append(None)
                block.data.append(None)
                block.lines.append(srcline)
                numeric_pos.append(entries)
                # (a long line was judged with ',' and ':' as separators, as the parser reads them)
                numeric_txt.append(raw if long_kind is None else
                                   raw.replace(",", " ").replace(":", " "))
                entries += 1
                continue
            if "(" in raw and "-" in raw:
                raw = _binary_minus_in_parens(raw)
            line = raw.replace(",", " ").replace(":", " ")
            if "{" in line:             # array attribute values: ref_coord { 1 0 0 }
                line = line.replace("{", " ").replace("}", " ")
            bad = _BAD_NUMBER.search(line)
            if bad:
                raise self.error(f"malformed number '{bad.group(0)}'", srcline, bad.start() + 1)
            if kind == "edges" and torus:
                line = self._strip_wraps(line, entries, sdim, srcline)
            if ";" in line:
                raise self.error("unexpected ';': one element per line", srcline,
                                 line.index(";") + 1)
            head = long_head if long_kind == "head" else (
                head_re(line) if len(line) <= _LONG else None)
            head_vals = None
            try:
                if head is not None and kind != "edges" or (head is not None and not torus):
                    nums_ = floats_of(line[:head.end()])
                    tail = line[head.end():]
                    items = _plain_tail(tail, head.end())
                    if items is None:
                        tree = line_parser().parse("0" + " " * (head.end() - 1) + tail,
                                                   start=start)
                        _, items = _LINE.transform(tree)
                    eid = int(line[:head.end()].split()[0])
                    head_vals = nums_[1:]        # (kept as an array: a body's 81,920 facets)
                else:
                    tree = line_parser().parse(line, start=start)
                    eid, items = _LINE.transform(tree)
            except UnexpectedInput as exc:
                col = exc.column if exc.column not in (None, -1) else None
                what = {"vertices": "vertex", "edges": "edge", "faces": "face",
                        "bodies": "body"}[kind]
                for fn in getattr(self, "_functions", ()):
                    call = re.search(r"\b" + re.escape(fn) + r"\s*\(", line, re.I)
                    if call:
                        raise self.error(f"not supported in pyevolver: calling the user "
                                         f"function {fn} in a datafile element line",
                                         srcline, call.start() + 1) from None
                raise self.error(self._describe(exc, line) + f" in {what} line", srcline,
                                 col) from None
            except VisitError as exc:
                if isinstance(exc.orig_exc, PyEvolverError):
                    raise self.error(str(exc.orig_exc), srcline,
                                     getattr(exc.orig_exc, "column", None)) from None
                raise
            if nesting_depth(items) > MAX_NESTING:
                raise self.error(f"expression nested more than {MAX_NESTING} levels deep",
                                 srcline)
            self._cur_line = line
            self._element(kind, block, eid, items, srcline, head_vals)
            entries += 1
        if numeric_txt:
            self._bulk(kind, block, numeric_pos, numeric_txt)

    def _bulk(self, kind, block, positions, texts):
        """Convert pure-numeric lines with one numpy call (no token list)."""
        lens = np.fromiter((len(t.split()) for t in texts), np.int64, len(texts))
        try:
            vals = floats_of(" ".join(texts))
        except ValueError:                     # cannot happen for lines that matched
            vals = np.empty(0)
        if vals.size != int(lens.sum()):
            raise self.error("could not read the numbers of this section", block.lines[positions[0]])
        self._bulk_values(kind, block, positions, vals, lens,
                          whole=len(positions) == len(block.ids))

    def _bulk_values(self, kind, block, positions, vals, lens, whole):
        """Store the numbers ``vals`` of the lines at ``positions`` (``lens``
        numbers each; ``whole``: they are all of the section's lines)."""
        starts = np.concatenate([[0], np.cumsum(lens)[:-1]])
        what = {"vertices": "vertex", "edges": "edge", "faces": "face", "bodies": "body"}[kind]

        def line_of(k):                 # source line of the k-th number
            return block.lines[positions[int(np.searchsorted(starts, k, side="right")) - 1]]
        idv = vals[starts]
        bad = np.nonzero(~((idv >= 1) & (idv <= MAX_ID)))[0]
        if len(bad):
            raise self.error(f"{what} id {idv[bad[0]]:.0f} is out of range (ids are 1 to "
                             f"{MAX_ID})", line_of(starts[bad[0]]), 1)
        if kind == "vertices":
            bad = np.nonzero(~np.isfinite(vals))[0]
            if len(bad):
                raise self.error(f"vertex coordinate {vals[bad[0]]:g} is not a finite number",
                                 line_of(bad[0]))
        else:
            frac = np.nonzero(vals != np.round(vals))[0]
            if len(frac):
                raise self.error(f"expected an integer id, got {vals[frac[0]]:g}",
                                 line_of(frac[0]))
            big = np.nonzero(np.abs(vals) > MAX_ID)[0]
            if len(big):
                raise self.error(f"{what}: id {vals[big[0]]:.0f} is out of range (ids are 1 to "
                                 f"{MAX_ID})", line_of(big[0]))
            if kind == "faces" and lens.max() - 1 > MAX_FACE_EDGES:
                k = int(np.argmax(lens))
                raise self.error(f"face {vals[starts[k]]:.0f} has {lens[k] - 1} edges; at most "
                                 f"{MAX_FACE_EDGES} are allowed", block.lines[positions[k]])
            vals = vals.astype(np.int64)
        ids = vals[starts].astype(np.int64)
        uniform = bool(np.all(lens == lens[0]))
        if uniform and whole:
            # the whole section is one table: keep it as arrays
            block.ids = ids
            block.data = vals.reshape(len(lens), int(lens[0]))[:, 1:]
            if kind != "vertices":      # ids within +-MAX_ID: int32, a copy without the ids
                block.data = block.data.astype(np.int32)    # (the load's peak memory)
            if kind == "vertices" and 1 <= block.data.shape[1] < self.scene.space_dimension:
                block.data = self._pad_coordinates(block.data, ids, block.lines)
            return
        sd = self.scene.space_dimension
        for p, i, st, n in zip(positions, ids.tolist(), starts.tolist(), lens.tolist()):
            block.ids[p] = i
            block.data[p] = vals[st + 1: st + n]
            if kind == "vertices" and 2 <= n <= sd:
                block.data[p] = self._pad_coordinates(block.data[p][None, :], [i],
                                                      [block.lines[p]])[0]

    def _pad_coordinates(self, data, ids, lines):
        """Vertices with fewer coordinates than the space dimension: a warning
        each, the missing ones 0 (REF: WARNING 1127 "Wrong number of
        coordinates for vertex")."""
        sd = self.scene.space_dimension
        for k, vid in enumerate(ids):
            self.warn(f"wrong number of coordinates for vertex {int(vid)}: "
                      f"{data.shape[1]} instead of {sd} (the rest are 0)", lines[k])
        out = np.zeros((data.shape[0], sd))
        out[:, :data.shape[1]] = data
        return out

    def _strip_wraps(self, line, pos, sdim, srcline):
        toks = line.split()
        if len(toks) >= 3 + sdim and all(t in ("*", "+", "-") for t in toks[3:3 + sdim]):
            self.scene.wraps[pos] = [{"*": 0, "+": 1, "-": -1}[t] for t in toks[3:3 + sdim]]
            return " ".join(toks[:3] + toks[3 + sdim:])
        return line

    def _undefined(self, exc, srcline):
        if exc.name in getattr(self, "_functions", ()):
            return self.error(f"not supported in pyevolver: calling the user function "
                              f"{exc.name} in a datafile element line", srcline, exc.col)
        words = set(self.scene.parameters) | {w for ws in _keywords().values() for w in ws}
        return self.error(f"undefined parameter '{exc.name}'" + did_you_mean(exc.name, words),
                          srcline, exc.col)


    def _unknown_words(self, etype, eid, items, qnames, srcline):
        """Edge, face and body lines: an unknown word is skipped with a warning
        (REF: WARNING 2110 / 2115 / 2119 "Unexpected token", the rest of the
        line is read); on a vertex line it is an error (REF: DATAFILE ERROR)."""
        sc = self.scene
        named = self._named_ids()
        keep = []
        text = getattr(self, "_cur_line", "")
        for it in items:
            col = getattr(it, "column", None)
            if isinstance(it, N.Var) and col and col >= 2 and col - 2 < len(text) and \
                    text[col - 2] in " \t" and not (
                    it.name in sc.parameters or it.name in N.CONSTANTS or it.name in named
                    or it.name in qnames or (etype, it.name) in sc.attributes):
                self.warn(f"{etype} {eid}: unexpected word '{it.name}' (ignored)",
                          srcline, it.column)
                continue
            keep.append(it)
        return keep

    def _element(self, kind, block, eid, items, srcline, head=None):
        """Store one element: its id, the values ``head`` (an array of the
        plain numbers after the id, or None) followed by ``items``, and its
        attributes."""
        sc = self.scene
        etype = {"vertices": "vertex", "edges": "edge", "faces": "facet", "bodies": "body"}[kind]
        qnames = set(sc.quantities) | set(sc.method_instances)
        if etype != "vertex" and any(isinstance(it, N.Var) for it in items):
            items = self._unknown_words(etype, eid, items, qnames, srcline)
        attrs = []
        i = 0
        n = len(items)
        # leading data expressions
        while i < n:
            it = items[i]
            if isinstance(it, float):
                i += 1
                continue
            if isinstance(it, tuple):
                break
            if isinstance(it, N.Var) and (it.name in qnames or (etype, it.name) in sc.attributes):
                break
            i += 1
        data = items[:i]
        while i < n:
            it = items[i]
            i += 1
            if isinstance(it, tuple) and it[0] == "kw":
                kw = it[1]
                args = []
                while i < n and not isinstance(items[i], tuple) and not (
                        isinstance(items[i], N.Var) and (items[i].name in qnames or
                                                         (etype, items[i].name) in sc.attributes)):
                    args.append(items[i])
                    i += 1
                attrs.append((kw, args, it[2]))
            elif isinstance(it, tuple) and it[0] == "name_neg":
                if it[1] not in qnames:
                    raise self.error(f"'{it[1]}-' is not a quantity or method instance",
                                     srcline, it[2])
                attrs.append(("quantity", [it[1], -1], it[2]))
            elif isinstance(it, N.Var) and it.name in qnames:
                attrs.append(("quantity", [it.name, 1], it.column))
            elif isinstance(it, N.Var) and (etype, it.name) in sc.attributes:
                size = sc.attributes[(etype, it.name)][1]
                vals = items[i:i + size]
                i += size
                attrs.append(("attribute", [it.name] + vals, it.column))
            else:
                col = getattr(it, "column", None)
                raise self.error(f"unexpected value after the attributes of {etype} {eid}",
                                 srcline, col)
        # evaluate
        try:
            values = [self._value(e, srcline, f"{etype} {eid}") for e in data]
        except _LocatedName as exc:
            raise self._undefined(exc, srcline) from None
        if head is not None and len(head):
            values = head.tolist() + values
            # the head's numbers checked at once when they are all good (else
            # one by one below, for the message about the first bad one)
            ok = np.isfinite(head).all()
            if ok and kind != "vertices":
                ok = bool((head == np.trunc(head)).all() and (np.abs(head) <= MAX_ID).all())
            checked = len(head) if ok else 0
        else:
            checked = 0
        if not 1 <= eid <= MAX_ID:
            raise self.error(f"{etype} id {eid} is out of range (ids are 1 to {MAX_ID})",
                             srcline, 1)
        if kind == "vertices" and len(values) < sc.space_dimension and values and \
                not any(kw == "boundary" for kw, _, _ in attrs):
            # REF: WARNING 1127 "Wrong number of coordinates", the rest are 0
            self.warn(f"wrong number of coordinates for vertex {eid}: "
                      f"{len(values)} instead of {sc.space_dimension} (the rest are 0)", srcline)
            values = values + [0.0] * (sc.space_dimension - len(values))
        if kind == "vertices":
            for v in values[checked:]:
                if not math.isfinite(v):
                    raise self.error(f"vertex {eid}: coordinate {v:g} is not a finite number",
                                     srcline)
        else:
            for v in values[checked:]:
                if not (math.isfinite(v) and v == int(v)):
                    raise self.error(f"expected an integer id in {etype} {eid}, got {v:g}", srcline)
                if abs(v) > MAX_ID:
                    raise self.error(f"{etype} {eid}: id {v:.0f} is out of range (ids are 1 to "
                                     f"{MAX_ID})", srcline)
            if kind == "faces" and len(values) > MAX_FACE_EDGES:
                raise self.error(f"face {eid} has {len(values)} edges; at most "
                                 f"{MAX_FACE_EDGES} are allowed", srcline)
            if kind == "bodies" and checked == len(values) > 64:
                values = head.astype(np.int64)      # a long facet list: an array (load memory)
            else:
                values = ([int(v) for v in values] if not checked else
                          head.astype(np.int64).tolist() + [int(v) for v in values[checked:]])
        cooked = []
        for kw, args, col in attrs:
            if kw == "quantity":
                cooked.append((kw, args))
                continue
            vals = []
            for a in (args[1:] if kw == "attribute" else args):
                what = args[0] if kw == "attribute" else f"{kw} of {etype} {eid}"
                try:
                    vals.append(self._value(a, srcline, what))
                except _LocatedName as exc:
                    raise self._undefined(exc, srcline) from None
            if kw == "attribute":
                cooked.append((kw, [args[0]] + vals))
            else:
                self._check_kw_args(kw, vals, etype, eid, srcline, col)
                cooked.append((kw, vals))
        block.ids.append(eid)
        block.data.append(values)
        block.lines.append(srcline)
        if cooked:
            block.attrs[len(block.ids) - 1] = cooked

    def _check_kw_args(self, kw, vals, etype, eid, srcline, col):
        """An attribute keyword's values: present, finite, integers where ids."""
        if kw in _KW_NEEDS_VALUE and not vals:
            raise self.error(f"{etype} {eid}: '{kw}' needs a value", srcline, col)
        for v in vals:
            if not math.isfinite(v):
                raise self.error(f"{etype} {eid}: the value of '{kw}' is not a finite number",
                                 srcline, col)
            if kw in _KW_INTEGER and (v != int(v) or abs(v) > MAX_ID):
                raise self.error(f"{etype} {eid}: '{kw}' needs an integer, got {v:g}",
                                 srcline, col)
