"""Elements of the command language: ``vertex[3]``, generators
(``edges where length > 0.1``, ``ff.vertex``), sub-elements and counts,
``define vertex attribute``.

Element references are :class:`~pyevolver.commands.values.ElemRef`; the
functions take the session (duck-typed: ``surface``, ``interp``,
``attr_types``).
"""
from __future__ import annotations

import numpy as np

from ..errors import ExpressionError, UnsupportedError
from ..geometry.kernels import edge_index
from ..model import string as SM
from ..model import records as MS
from .columns import where_mask
from .registry import register
from .values import ElemRef, SessionLike, as_int, is_true


def count(session: SessionLike, kind):
    """The number of ``kind`` elements (vertex, edge, facet, body)."""
    s = session.surface
    return {"vertex": s.nv, "edge": s.ne, "facet": s.n_facets, "body": s.bodies.n}[kind]


def element(session: SessionLike, kind, index):
    """``kind[index]`` by id (1-based; negative: reversed orientation)."""
    k = as_int(index, f"a {kind} index")
    n = count(session, kind)
    sign = -1 if k < 0 else 1
    attrs = {"vertex": "vattr", "edge": "eattr", "facet": "fattr"}.get(kind)
    ids = getattr(session.surface, attrs).get("id") if attrs else None
    if ids is not None:                     # ids with gaps after deletions
        hit = np.nonzero(ids == abs(k))[0]
        if k == 0 or not len(hit):
            raise ExpressionError(f"{kind}[{k}] does not exist")
        return ElemRef(kind, int(hit[0]), sign)
    if k == 0 or abs(k) > n:
        raise ExpressionError(f"{kind}[{k}] does not exist ({kind} ids are 1..{n})")
    return ElemRef(kind, abs(k) - 1, sign)


def generate(session: SessionLike, gen, env):
    """Elements of a generator, with its ``where`` filter applied."""
    els = gen_base(session, gen.base, env)
    if gen.where is None:
        return els
    mask = where_mask(session, gen, els, env)      # (simple conditions: at once)
    if mask is not None:
        out = [el for el, keep in zip(els, mask.tolist()) if keep]
        session.counts["where"] = len(out)
        return out
    out = []
    tick = session.interp.tick
    for el in els:
        tick()
        with env.element(el, gen.var):
            v = gen.where.ev(env)
        if is_true(v):
            out.append(el)
    session.counts["where"] = len(out)          # where_count: the last where's hits
    return out


def gen_base(session: SessionLike, base, env):
    """The elements of a generator's base (``all``, ``index``, ``var``,
    ``sub``), before ``where``."""
    tag = base[0]
    if "facetedge" in base[1:3]:
        raise UnsupportedError("facetedge elements")
    if tag == "var":
        el = env.lookup(base[1])
        if not isinstance(el, ElemRef):
            raise ExpressionError(f"'{base[1]}' is not an element")
        return [el]
    if tag == "all":
        return [ElemRef(base[1], i) for i in range(count(session, base[1]))]
    if tag == "index":
        return [element(session, base[1], env.session.interp.value(base[2]))]
    if tag == "sub":
        parents = gen_base(session, base[1], env)
    else:
        parent = env.lookup(base[1])
        if not isinstance(parent, ElemRef):
            raise ExpressionError(f"'{base[1]}' is not an element")
        parents = [parent]
    kind, idx = base[2], base[3]
    out = []
    for p in parents:
        subs = sub_elements(session, p, kind)
        if idx is not None:
            k = as_int(env.session.interp.value(idx), f"a {kind} index")
            if k < 1 or k > len(subs):
                raise ExpressionError(f"{p}.{kind}[{k}] does not exist")
            subs = [subs[k - 1]]
        out.extend(subs)
    return out


def sub_elements(session: SessionLike, el, kind):
    """The ``kind`` elements of ``el`` (``ee.vertex``, ``ff.edge``,
    ``vv.facet``), in REF's order."""
    check_alive(session, el)
    s = session.surface
    i = el.i
    if s.string and "facet" in (el.kind, kind) and el.kind != "body":
        return _string_sub_elements(session, el, kind)
    if s.simplex and el.kind in ("vertex", "facet") and kind in ("vertex", "facet", "edge"):
        if el.kind == "facet" and kind == "vertex":
            return [ElemRef("vertex", int(v)) for v in s.SF[i]]
        if el.kind == "vertex" and kind == "facet":
            # REF: the newest facet first
            fs = np.nonzero((s.SF == i).any(axis=1))[0][::-1]
            return [ElemRef("facet", int(f)) for f in fs]
        if kind == "edge":
            return []          # the simplex model keeps no edges
    if el.kind == "vertex":
        if kind == "edge" and "ring_time" in s.eattr:
            return [ElemRef("edge", e, g) for e, g in SM.vertex_edges(s, i)]
        if kind == "edge":
            # oriented away from the vertex (oid < 0 where it is the head),
            # in the Evolver's ring order (surface.vertex_rings)
            es, end = np.nonzero(s.E == i)
            es = es[np.argsort(MS.vertex_edge_rank(s)[es, end], kind="stable")]
            es = list(dict.fromkeys(es.tolist()))
            return [ElemRef("edge", int(e), 1 if s.E[e, 0] == i else -1) for e in es]
        if kind == "facet":
            fs, corner = np.nonzero(s.F == i)
            fs = fs[np.argsort(MS.vertex_facet_rank(s)[fs, corner], kind="stable")]
            return [ElemRef("facet", int(f)) for f in dict.fromkeys(fs.tolist())]
    if el.kind == "edge":
        if kind == "vertex":
            a, b = s.E[i]
            if el.sign < 0:
                a, b = b, a
            return [ElemRef("vertex", int(a)), ElemRef("vertex", int(b))]
        if kind == "facet":
            # oriented like the edge: oid < 0 where the facet runs against it
            idx, sgn = edge_index(s.FE)
            out = []
            for f in np.nonzero((idx == i).any(axis=1))[0]:
                g = int(sgn[f][np.nonzero(idx[f] == i)[0][0]]) * el.sign
                out.append(ElemRef("facet", int(f), g))
            # REF's loop order of a two-facet edge: the facet running along
            # the edge first, unless the loop is known to start with the
            # other (surface.along_first)
            first = 1 if len(out) != 2 or MS.along_first(s)[i] else -1
            out.sort(key=lambda r: -r.sign * el.sign * first)
            return out
    if el.kind == "facet":
        if kind == "vertex":
            return [ElemRef("vertex", int(v)) for v in s.F[i]]
        if kind == "edge":
            idx, sgn = edge_index(s.FE[i])
            return [ElemRef("edge", int(e), int(g)) for e, g in zip(idx, sgn)]
        if kind == "body":
            col = s.bodies.facet_matrix[:, i].tocoo()
            return [ElemRef("body", int(b)) for b in col.row]
    if el.kind == "body" and kind == "facet":
        row = s.bodies.facet_matrix.getrow(i).tocoo()
        return [ElemRef("facet", int(f), int(np.sign(v))) for f, v in zip(row.col, row.data)]
    raise ExpressionError(f"{el.kind} has no {kind}s")


def _string_sub_elements(session: SessionLike, el, kind):
    """Facet navigation in the string model (facets are edge chains)."""
    s = session.surface
    i = el.i
    if el.kind == "facet":
        if kind == "vertex":
            return [ElemRef("vertex", v) for v in SM.chain_vertices(s, i, el.sign)]
        if kind == "edge":
            enc = SM.chain(s, i)
            if el.sign < 0:
                enc = ~enc[::-1]
            return [ElemRef("edge", int(e if e >= 0 else ~e), 1 if e >= 0 else -1)
                    for e in enc]
        if kind == "body":
            col = s.bodies.facet_matrix[:, i].tocoo()
            return [ElemRef("body", int(b)) for b in col.row]
    if el.kind == "edge" and kind == "facet":
        return [ElemRef("facet", f, g * el.sign) for f, g in SM.facets_of_edge(s, i)]
    if el.kind == "vertex" and kind == "facet":
        owner, e, _, _, _ = SM.facet_entries(s)
        mine = (s.E[e] == i).any(axis=1)
        return [ElemRef("facet", int(f)) for f in np.unique(owner[mine])]
    raise ExpressionError(f"{el.kind} has no {kind}s")


def check_alive(session: SessionLike, el):
    """An element reference kept across a command that removed elements
    (``foreach ... do { delete ...; print vv.id }``) may point past the
    end: refused by name."""
    if el.kind in ("vertex", "edge", "facet", "body") and el.i >= count(session, el.kind):
        raise ExpressionError(f"the {el.kind} no longer exists (deleted by this command)")


def define_attribute(session: SessionLike, kind, name, typ, shape):
    """``define vertex attribute name real[3]`` at run time."""
    s = session.surface
    if typ not in ("real", "integer"):
        raise UnsupportedError(f"{typ} element attributes", "real and integer are supported")
    if kind == "facetedge":           # declared; facetedges themselves are refused when used
        session.attr_types[(kind, name)] = typ
        return
    n = count(session, kind)
    key = (kind, name)
    new = np.zeros((n,) + tuple(shape)) if shape else np.zeros(n)
    old = s.extra.get(key)
    if old is not None:
        if old.shape == new.shape:
            session.attr_types[key] = typ
            return
        if old.ndim == new.ndim:               # resizing keeps the values
            sl = tuple(slice(0, min(a, b)) for a, b in zip(old.shape, new.shape))
            new[sl] = old[sl]
    s.extra[key] = new
    session.attr_types[key] = typ


@register("define", usage="define vertex|edge|facet|body attribute NAME real|integer[[n]...]",
          statement="define_attr", help="a new element attribute", family="elements")
def _x_define_attr(interp, node):
    _, kind, name, typ, dims = node
    n = count(interp.session, kind) if kind != "facetedge" else 1
    shape = interp.sizes(dims, f"define {kind} attribute {name}", per=max(n, 1))
    define_attribute(interp.session, kind, name, typ, shape)
