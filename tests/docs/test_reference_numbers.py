"""The measured numbers of docs/differences.md and docs/supported.md,
regenerated: each claim below is a piece of a doc's text with ``{…}`` where
numbers stand, and a function that measures them again (evolver-nox-d run
live, with or without its worker thread as the doc says, and pyevolver at
the same small size); the text formatted with the measured values must be
in the doc.  ``test_every_measured_number_is_claimed`` keeps the list
complete: every decimal number of three or more significant digits in the
two docs lies inside a claim's text or is listed in ``NOT_MEASURED`` (the
version, thresholds chosen by hand) — a new number needs a claim.

Expected values come from the reference Evolver and from pyevolver run
again at the documented size, never from a table in this file; REF runs do
not skip in CI (the ``evolver`` fixture fails there when REF is missing).
The same pattern for the studies' numbers is test_documented_numbers.py."""
import importlib.util
import io
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest

from conftest import EXAMPLES
from pyevolver import Session

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
DOCS = os.path.join(ROOT, "docs")
DATA = os.path.join(ROOT, "tests", "data")
E = "printf \"RES %.17g\\n\", total_energy\n"


def _ex(name):
    return os.path.join(EXAMPLES, name)


def ref(evolver, fe, cmds, threads=False, cwd=None):
    """REF's transcript lines for ``cmds`` on ``fe``: ``-p1`` with
    ``threads``, no worker thread otherwise (REF's default)."""
    args = [evolver] + (["-p1"] if threads else []) + [fe]
    p = subprocess.run(args, input=cmds + "\nq\nq\n", capture_output=True, text=True,
                       timeout=120, cwd=cwd, errors="replace")
    return p.stdout.splitlines()


def ours(fe, cmds):
    """pyevolver's output lines for ``cmds`` on ``fe`` (in process)."""
    out = io.StringIO()
    Session.load(fe, out=out, err=io.StringIO()).run(cmds)
    return out.getvalue().splitlines()


def res(lines):
    """The numbers of the ``RES`` lines, in order."""
    return [float(x) for ln in lines if ln.startswith("RES ") for x in ln.split()[1:]]


def grab(lines, pattern):
    """Every match of ``pattern``'s first group in ``lines`` as floats."""
    return [float(m.group(1)) for ln in lines for m in [re.search(pattern, ln)] if m]


# -- the measurements ----------------------------------------------------------------------------

CATBODY8 = "u\nbody[1].target := 8\ng 5\nr\ng 5\nV\nV\nr\ng 10\n"


def _saddle(evolver, tmp, fe, before):
    cmds = before + E + "saddle\n" + E
    r, o = ref(evolver, fe, cmds, cwd=tmp), ours(fe, cmds)
    step = r"^stepsize (\S+)"
    return [grab(r, step)[0], res(r)[1], grab(o, step)[0], res(o)[1], res(o)[0]]


def saddle_catbody(evolver, tmp):
    return _saddle(evolver, tmp, _ex("catbody.fe"), CATBODY8)


def saddle_cube(evolver, tmp):
    v = _saddle(evolver, tmp, _ex("cube.fe"), "r\nr\nr\nr\ng 10\n")[:4]
    v[2] = abs(v[2])        # (pyevolver's sign is its eigenvector's, which round-off picks)
    return v


COUNTS = r"Eigencounts:\s+(\d+) <,\s+(\d+) ==,\s+(\d+) >"
PROBE = "r\nr\nr\nr\ng 10\nhessian_normal off\neigenprobe 0\neigenprobe -1e-6\neigenprobe 1e-6\n"


def _counts(lines):
    return [tuple(int(x) for x in m.groups()) for ln in lines
            for m in [re.search(COUNTS, ln)] if m]


def eigenprobe_ref(evolver, tmp):
    c = _counts(ref(evolver, _ex("cube.fe"), PROBE, cwd=tmp))
    return [*c[0], c[0][1], c[1][0], c[2][0]]


def eigenprobe_ours(evolver, tmp):
    return list(_counts(ours(_ex("cube.fe"), PROBE))[0])


def _vpop():
    spec = importlib.util.spec_from_file_location(
        "vpop_tests", os.path.join(ROOT, "tests", "remesh", "test_vpop.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def prism6_pop(evolver, tmp):
    V = _vpop()
    P, edges, c = V._prism(6, 1)
    fe = str(V._frame_cone(pathlib.Path(tmp, "prism6.fe"), P, edges, c))
    cmds = "o\ng 20\n" + E
    a, b = res(ours(fe, cmds))[0], res(ref(evolver, fe, cmds, threads=True, cwd=tmp))[0]
    return [a, b, f"{abs(a - b) / b:.1e}".replace("e-0", "e-")]


def runge_kutta(evolver, tmp):
    cmds = "runge_kutta\nr\nm 0.1\ng 1\n" + E
    r, o = res(ref(evolver, _ex("quad.fe"), cmds, True, tmp)), res(ours(_ex("quad.fe"), cmds))
    assert o == pytest.approx(r, rel=1e-13)
    return r


def _sheet(tmp):
    spec = importlib.util.spec_from_file_location(
        "curv_torus_tests", os.path.join(ROOT, "tests", "methods", "test_curvature_torus.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    fe = os.path.join(tmp, "sheet.fe")
    with open(fe, "w") as fh:
        fh.write(mod.torus_sheet(["star_perp_sq_mean_curvature"], "star_perp_sq_mean_curvature"))
    return fe


def torus_sheet_hessian(evolver, tmp):
    fe, cmds = _sheet(tmp), "g 3\nhessian\n" + E
    single = res(ref(evolver, fe, cmds, False, tmp))[0]
    o = res(ours(fe, cmds))[0]
    assert o == pytest.approx(single, rel=1e-12)           # "single-threaded REF lands where ..."
    return [o, res(ref(evolver, fe, cmds, True, tmp))[0]]


def _threads(evolver, tmp, fe, cmds):
    """(REF single-threaded = pyevolver, REF with -p1)."""
    single, o = res(ref(evolver, fe, cmds, False, tmp))[0], res(ours(fe, cmds))[0]
    assert o == pytest.approx(single, rel=1e-12)
    return [single, res(ref(evolver, fe, cmds, True, tmp))[0]]


def mylar_and_string_hessian(evolver, tmp):
    return (_threads(evolver, tmp, _ex("mylarcube.fe"), "g 5\nhessian\n" + E)
            + _threads(evolver, tmp, os.path.join(DATA, "string_chain.fe"), "g 5\nhessian\n" + E))


def symtest_volumes(evolver, tmp):
    cmds = 'printf "RES %.17g %.17g\\n", body[1].volume, body[2].volume\n'
    r = res(ref(evolver, _ex("symtest.fe"), cmds, True, tmp))
    assert res(ours(_ex("symtest.fe"), cmds)) == pytest.approx(r, rel=1e-14)
    return r


def hessian_seek_string(evolver, tmp):
    fe = os.path.join(DATA, "string_chain.fe")
    a, b = "hessian_seek\n" + E, "g 5\nhessian_seek\n" + E
    after = res(ours(fe, b))[0]
    assert after == pytest.approx(res(ref(evolver, fe, b, False, tmp))[0], rel=1e-13)
    return [res(ours(fe, a))[0], res(ref(evolver, fe, a, False, tmp))[0], after]


def simplex_ref(evolver, tmp):
    fe = _ex("simplex3.fe")
    u = res(ref(evolver, fe, 'r\nprintf "RES %d\\n", facet_count\nu\n'
                             'printf "RES %d\\n", facet_count\n', True, tmp))
    ell = res(ref(evolver, fe, 'r\nl 0.5\nprintf "RES %d %.17g\\n", facet_count, total_area\n',
                  True, tmp))
    return [u[1], u[0], ell[0], ell[1]]


def quadratic_ref(evolver, tmp):
    vol = res(ref(evolver, _ex("cube.fe"),
                  'M 2\nr\ng 5\nu\nprintf "RES %.17g\\n", body[1].volume\n', True, tmp))
    gap = res(ref(evolver, _ex("tankex.fe"), 'M 2\nprintf "RES %.17g\\n", gap_quant.value\n',
                  True, tmp))
    return vol + gap


def catbody_hessian(evolver, tmp):
    fe = _ex("catbody.fe")
    a, b = "r\ng 10\nhessian\n" + E, "g 5\nhessian\n" + E
    after_r = [res(ref(evolver, fe, a, True, tmp))[0], res(ours(fe, a))[0]]
    assert res(ref(evolver, fe, a, False, tmp))[0] == pytest.approx(after_r[0], rel=1e-13)
    p1 = res(ref(evolver, fe, b, True, tmp))[0]
    assert res(ours(fe, b))[0] == pytest.approx(p1, rel=1e-13)  # "pyevolver's step"
    return after_r + [res(ref(evolver, fe, b, False, tmp))[0], p1]


def twointor_k(evolver, tmp):
    fe = _ex("twointor.fe")
    cmds = ('printf "RES %.17g\\n", total_area\nK 0.2\n'
            'printf "RES %.17g %.17g %.17g\\n", total_area, body[1].volume, body[2].volume\n')
    r = res(ref(evolver, fe, cmds, True, tmp))
    assert res(ours(fe, cmds)) == pytest.approx(r, rel=1e-12)
    return r


def curv_mound_steps(evolver, tmp):
    fe = os.path.join(DATA, "curv_mound.fe")
    cmds = "r\ng 100\n" + ("hessian\n" + E) * 4
    single = res(ref(evolver, fe, cmds, False, tmp))
    assert res(ours(fe, cmds)) == pytest.approx(single, rel=1e-10)
    return single + res(ref(evolver, fe, cmds, True, tmp))


def _cube_with(tmp, method):
    with open(_ex("cube.fe")) as fh:
        text = fh.read()
    fe = os.path.join(tmp, f"cube_{method}.fe")
    with open(fe, "w") as fh:
        fh.write(text.replace("vertices", f"quantity qq energy modulus 0.1 method {method} "
                                          "global\n\nvertices", 1))
    return fe


def sq_gauss_normal_mode(evolver, tmp):
    fe = _cube_with(tmp, "sq_gauss_curvature")
    ritz = r"^\s*\d+\.\s+(-?\d+\.\d+)$"
    r = grab(ref(evolver, fe, "r\ng 5\nritz(-100,6)\n", False, tmp), ritz)
    o = grab(ours(fe, "r\ng 5\nritz(-100,6)\n"), ritz)
    assert o[0] == pytest.approx(o[2], rel=1e-10)                   # a triple
    step = "r\ng 5\nhessian\n" + E
    return r[:3] + [o[0], res(ref(evolver, fe, step, False, tmp))[0], res(ours(fe, step))[0]]


def sphere_area_volume(evolver, tmp):
    """The 320-facet icosphere vesicle (star_perp bending, the area fixed by
    a quantity) told to lose 4% of its volume: REF's restoring aborts at
    every step (the area's and the volume's gradients are parallel on the
    sphere) and its volume stays; pyevolver's least-squares restoring
    reaches the target."""
    from pyevolver.studies.meshes import icosphere, write_fe
    X, F = icosphere(2)
    area = float(0.5 * np.linalg.norm(np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]),
                                      axis=1).sum())
    hdr = ("quantity bend energy modulus 1 method star_perp_sq_mean_curvature global\n"
           f"quantity surf fixed = {area!r} method facet_area global")
    fe = write_fe(os.path.join(tmp, "sphere320.fe"), X, F, header=hdr, face_attrs="tension 0")
    with open(fe, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F))) + " volume 4\n")
    V = 'printf "RES %.17g\\n", body[1].volume\n'
    cmds = "set body target body[1].volume\n" + V + "set body target 3.9\ng 3\n" + V
    r, o = res(ref(evolver, fe, cmds, cwd=tmp)), res(ours(fe, cmds))
    assert o[0] == pytest.approx(r[0], rel=1e-14)
    return [r[0], r[1], o[1]]


# -- the claims: (doc, text with {format} for each number, the measurement, slow) --------------

CLAIMS = [
    # (pyevolver's saddle steps within a multiple eigenvalue's eigenspace: its
    # direction, hence the step's last digits and sign, moves with round-off
    # in the Hessian; quoted to four and six digits)
    ("differences.md", "saddle`: REF stepsize {:.6g}, energy {:.9g}; pyevolver {:.4g}, {:.6g}, "
                       "from {:.9g};", saddle_catbody, False),
    ("differences.md", "cube.fe `r` ×4, `g 10`: REF {:.6g}, {:.9g}; pyevolver ±{:.6g}, {:.9g};",
     saddle_cube, False),
    ("differences.md", "eigenprobe 0` gives REF `{} <, {} ==, {} >` ({} small pivots)",
     eigenprobe_ref, False),
    ("differences.md", "REF's own `eigenprobe ±1e-6` ({} and {} below)",
     lambda ev, t: eigenprobe_ref(ev, t)[4:], False),
    ("differences.md", "and pyevolver `{} <, {} ==, {} >` (the three translations)",
     eigenprobe_ours, True),
    ("differences.md", "(energy after `o; g 20`: {:.15g} against REF's {:.15g}, {} relative)", prism6_pop, False),
    ("differences.md", "g 1`: {:.15g} in both;", runge_kutta, False),
    ("differences.md", "`g 3; hessian` lands at energy {:.12g} in pyevolver (the flat minimum is "
                       "1: the exact Newton step of a Hessian checked against differences of the "
                       "gradient) and at {:.12g} in REF with `-p1`", torus_sheet_hessian, False),
    ("differences.md", "exact Hessian and step: mylarcube.fe `g 5; hessian` {:.15g} (pyevolver's "
                       "step; `-p1`: {:.15g}), string_chain.fe `g 5; hessian` {:.15g} (`-p1`: "
                       "{:.15g})", mylar_and_string_hessian, False),
    ("supported.md", "symtest.fe {:.5g} / {:.5g})", symtest_volumes, False),
    ("supported.md", "`hessian_seek` on string_chain.fe right after loading ends at energy "
                     "{:.6g} where REF (single-threaded) ends at {:.6g} (after `g 5` both end at "
                     "{:.15g})", hessian_seek_string, False),
    ("supported.md", "`r; u` gives {:.0f} facets from {:.0f}, `r; l 0.5` {:.0f} facets and area {:.3g})",
     simplex_ref, False),
    ("supported.md", "(REF's volume afterwards {:.6g};", lambda ev, t: quadratic_ref(ev, t)[:1],
     False),
    ("supported.md", "(tankex.fe after `M 2`: REF's gap_quant {:.5g},",
     lambda ev, t: quadratic_ref(ev, t)[1:], False),
    ("supported.md", "(catbody `r; g 10; hessian`: REF {:.14g}, pyevolver {:.15g})",
     lambda ev, t: catbody_hessian(ev, t)[:2], False),
    ("supported.md", "where single-threaded REF lands at {:.6g} and REF with `-p1` at {:.15g}, "
                     "pyevolver's step to the last digit", lambda ev, t: catbody_hessian(ev, t)[2:],
     False),
    ("supported.md", "the area jumps from {:.3g} to {:.4g} in both", twointor_k, False),
    ("supported.md", "so the volumes are REF's (twointor.fe: {:.4g}, {:.4g})",
     lambda ev, t: twointor_k(ev, t)[2:], False),
    ("supported.md", "four `hessian` steps give {:.6g}, {:.7g}, {:.12g}, {:.12g} in pyevolver "
                     "(quadratic) and in REF single-threaded (with `-p1` REF's threaded Hessian "
                     "gives {:.6g}, {:.6g}, {:.6g}, {:.6g})", curv_mound_steps, True),
    ("differences.md", "REF's volume is {:.6g} before and {:.6g} after, pyevolver's {:.6g} after",
     sphere_area_volume, False),
    ("supported.md", "values {:.5g}, {:.5g}, {:.5g}, …; pyevolver's come in triples, {:.5g} three "
                     "times) and its step lands at {:.6g} where pyevolver's lands at {:.6g}",
     sq_gauss_normal_mode, False),
]

#: numbers of three or more significant digits in the two docs that are no measurement
NOT_MEASURED = {
    "2.70": "the Evolver's version",
}

_NUM = re.compile(r"(?<![\w.])[−-]?\d+(?:\.\d+)?(?:e[−+-]?\d+)?(?![\w])")


def _norm(text):
    return re.sub(r"\s+", " ", text).replace("−", "-")


def _doc(name):
    with open(os.path.join(DOCS, name), encoding="utf-8") as fh:
        return _norm(fh.read())


def _pattern(template):
    """A regex matching ``template`` with any number where a field stands."""
    parts = re.split(r"\{[^{}]*\}", _norm(template))
    return r"[+-]?\d[\d,]*(?:\.\d+)?(?:e[+-]?\d+)?%?".join(re.escape(p) for p in parts)


def _significant(tok):
    digits = re.sub(r"\D", "", tok.split("e")[0].replace("−", "-"))
    return len(digits.lstrip("0"))


@pytest.mark.parametrize("claim", [pytest.param(c, marks=pytest.mark.slow) if c[3] else c
                                   for c in CLAIMS], ids=[c[1][:40] for c in CLAIMS])
def test_the_docs_quote_the_measurement(claim, evolver, tmp_path):
    doc, template, measure, _ = claim
    expected = _norm(template.format(*measure(evolver, str(tmp_path))))
    assert expected in _doc(doc), f"{doc}: measured now: {expected}"


@pytest.mark.parametrize("doc", ["differences.md", "supported.md"])
def test_every_measured_number_is_claimed(doc):
    text = _doc(doc)
    for c in CLAIMS:
        if c[0] == doc:
            text, n = re.subn(_pattern(c[1]), " ", text)
            assert n == 1, f"{doc}: the text of a claim is not there once: {c[1]}"
    left = sorted({t for t in _NUM.findall(text) if "." in t or "e" in t}
                  - set(NOT_MEASURED))
    left = [t for t in left if _significant(t) >= 3]
    assert not left, (f"{doc}: numbers no test regenerates: {left}; add a claim to "
                      "tests/docs/test_reference_numbers.py or write the text without them")
