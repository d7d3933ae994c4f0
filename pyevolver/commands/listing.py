"""Reports: ``list gen`` (datafile-style lines in REF's formats) and the
``v`` table of bodies and quantities.
"""
from __future__ import annotations

import math

import numpy as np

from ..expr import nodes as N
from ..geometry.kernels import edge_index
from ..model import string as SM
from ..model.symmetry import encode_torus
from . import constraints, elements
from .values import SessionLike


def list_elements(session: SessionLike, gen, env):
    """``list gen``: datafile-style lines in REF's formats (measured on
    evolver-nox-d: mound, catbody, column, twointor, string files)."""
    els = elements.generate(session, gen, env)
    kind = gen.kind or (els[0].kind if els else None)
    fn = {"vertex": _list_vertex, "edge": _list_edge,
          "facet": _list_facet, "body": _list_body}.get(kind)
    if fn is None:
        return
    session.note({"vertex": "// Id               X                Y" +
                ("               Z" if session.surface.sdim >= 3 else ""),
                "edge": "// Id    endpoints",
                "facet": "// Id      vertices" if session.surface.simplex else "// Id    edges",
                "body": "// Id    facets"}[kind] + "\n")
    for el in els:
        session.write(fn(session, el.i) + "\n")


def _wrapped(items, indent):
    """Ids ``"%d "`` each, a `` \\`` line break after every tenth (REF)."""
    out = []
    for k, it in enumerate(items, 1):
        out.append(f"{it} ")
        if k % 10 == 0:
            out.append("\\\n" + " " * indent)
    return "".join(out)


def _list_vertex(session: SessionLike, i):
    s = session.surface
    vid = s.ids("vertex")
    sd = s.sdim
    bnd = s.vattr.get("boundary")
    if bnd is not None and bnd[i]:
        b = s.boundaries[int(bnd[i])]
        par = " ".join(f"{p:17.15g}" for p in s.vattr["params"][i, :b.nparams])
        xyz = "".join(f" {x:17.15g}" for x in s.X[i, :sd])
        label = constraints.boundary_label(session, int(bnd[i]))
        line = f"{vid[i]:3d}  {par}  boundary {label}  /* ({xyz}) */"
    else:
        line = f"{vid[i]:3d}  " + " ".join(f"{x:17.15g}" for x in s.X[i, :sd])
    cons = constraints.in_order(session, "vertex", i, [c for c in sorted(s.vcon) if s.vcon[c][i]])
    if cons:
        line += "  constraints " + " ".join((constraints.constraint_label(session, c) for c in cons)) + " "
    if s.vattr["fixed"][i]:
        line += " fixed "
    if "axial_point" in s.vattr and s.vattr["axial_point"][i]:         # model.groups
        line += " axial_point "
    return line + _extra_text(session, "vertex", i)


def _extra_text(session: SessionLike, kind, i):
    """Defined attributes as REF lists them: `` name value`` each (reals
    ``%2.15g``, integers ``%d``, arrays in braces)."""
    out = []
    for (k, name), arr in session.surface.extra.items():
        if k != kind:
            continue
        integer = session.attr_types.get((k, name)) == "integer"
        fmt = (lambda v: "%d" % int(v)) if integer else (lambda v: "%2.15g" % v)
        v = arr[i]
        if np.ndim(v):
            txt = "{" + ",".join(fmt(x) for x in np.ravel(v)) + "} "
        else:
            txt = fmt(v)
        out.append(f" {name} {txt}")
    return "".join(out)


def _colour_name(c):
    names = {v: k for k, v in N.COLOURS.items() if k != "transparent"}
    return names.get(int(c), str(int(c)))


def _list_edge(session: SessionLike, i):
    s = session.surface
    t = session.totals
    vid, eid = s.ids("vertex"), s.ids("edge")
    a, b = vid[s.E[i]]
    line = f"{eid[i]:3d}   {a:5d} {b:4d}    "
    if s.order == 2:                      # REF: "/*midpt*/  16" in the quadratic model
        line += f"  /*midpt*/ {vid[s.midv[i]]:3d} "
    w = s.eattr.get("wrap")
    if "wrap_code" in s.eattr:                  # the other groups' codes (model.groups)
        line += f" wrap {int(s.eattr['wrap_code'][i])} "
    elif w is not None and s.symmetry_group is not None:      # REF: the group element's code
        line += f" wrap {int(encode_torus(w[i:i + 1])[0])} "
    elif w is not None:
        line += " " + " ".join({0: "*", 1: "+", -1: "-"}.get(int(x), "?")
                               for x in w[i, :s.sdim])
    ten = s.edge_tension[i]
    if ten != (1.0 if s.string else 0.0):
        line += f"  density {ten:g} "
    cons = constraints.in_order(session, "edge", i, [c for c in sorted(s.econ) if s.econ[c][i]])
    if cons:
        line += "  constraints " + " ".join(
            ("-" if s.econ[c][i] < 0 else "") + constraints.constraint_label(session, c) for c in cons) + " "
    eb = s.eattr.get("boundary")
    if eb is not None and eb[i]:
        line += f"  boundary {constraints.boundary_label(session, int(eb[i]))} "
    if s.eattr["fixed"][i]:
        line += "fixed "
    if s.eattr["no_refine"][i]:
        line += " no_refine "
    col = s.eattr.get("color")
    if col is not None and col[i] != 0:
        line += f" color {_colour_name(col[i])} "
    line += f" /*length {t.edge_length[i]:g}*/ "
    eorig = s.eattr.get("original")
    if eorig is not None and eorig[i] and eorig[i] != eid[i]:
        line += f" original {eorig[i]}"
    return line + _extra_text(session, "edge", i)


def _list_facet(session: SessionLike, i):
    s = session.surface
    t = session.totals
    eid, fid = s.ids("edge"), s.ids("facet")
    if s.simplex:
        return _list_simplex_facet(session, i)
    if s.string:
        enc = SM.chain(s, i)
        edges = [int(eid[e]) if e >= 0 else -int(eid[~e]) for e in enc]
        area = t.sfacet_area[i]
    else:
        idx, sgn = edge_index(s.FE[i])
        edges = [int(eid[e] * g) for e, g in zip(idx, sgn)]
        area = t.facet_area[i]
    attrs = ""
    cons = [c for c in sorted(s.fcon) if s.fcon[c][i]]
    if cons:
        attrs += " constraints " + " ".join((constraints.constraint_label(session, c) for c in cons)) + "  "
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
        attrs += f"color {_colour_name(fc)} "
    if bc != fc:
        attrs += (" " if attrs else "") + f"backcolor {_colour_name(bc)} "
    line = (f"{fid[i]:3d}   " + _wrapped(edges, 15) + attrs + (" " if attrs else "")
            + f"/*area {area:g}*/")
    orig = s.fattr["original"][i]
    if orig and orig != fid[i]:
        line += f" original {orig}"
    return line + _extra_text(session, "facet", i)


def _list_simplex_facet(session: SessionLike, i):
    """The simplex model: the facet's vertices (REF: ``%3d``, then ``%4d`` each)."""
    s = session.surface
    fid, vid = s.ids("facet"), s.ids("vertex")
    line = f"{fid[i]:3d}  " + "".join(f"{int(vid[v]):4d}" for v in s.SF[i])
    if s.facet_tension[i] != 1.0:
        line += f"  density {s.facet_tension[i]:g} "
    if s.fattr["fixed"][i]:
        line += " fixed "
    line += f" /*area {session.totals.facet_area[i]:g}*/"
    orig = s.fattr["original"][i]
    if orig and orig != fid[i]:
        line += f" original {orig}"
    return line + _extra_text(session, "facet", i)


def _list_body(session: SessionLike, i):
    s = session.surface
    t = session.totals
    b = s.bodies
    fid = s.ids("facet")
    ob, of, osg = b.occurrences
    sel = np.nonzero(ob == i)[0]
    facets = [int(fid[f] * g) for f, g in zip(of[sel], osg[sel])]
    line = f"{i + 1:3d}       " + _wrapped(facets, 11)
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
    return line + _extra_text(session, "body", i)


def show_vol(session: SessionLike):
    """The ``v`` report (spec §9.3 formats)."""
    s = session.surface
    t = session.totals
    b = s.bodies
    lines = []
    qs = [q for q in s.quantities.values() if q.kind != "instance"]
    if not b.n and not qs:
        # REF converts to named quantities in a symmetry group other than the
        # torus, and then prints nothing here
        return "" if s.symmetry_group not in (None, "torus") else "No bodies or quantities.\n"
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
