"""Riemannian metrics against evolver-nox-d, run live (issue 23): METRIC in
the string model (metric.fe) and on a soapfilm with constraints and
INTEGRAL_ORDER 7 (quadm.fe and its commented-out nonidentity metric,
tests/data/quadm_curved.fe), CONFORMAL_METRIC on small hand-written files.
The same script runs in both programs; every energy of the ``g`` lines and
every printed length, area and coordinate agrees within 1e-6 relative
(measured: 1e-13 or better).  Dumps: pyevolver's loads in REF with the same
energy (REF's dumps of metric.fe and quadm.fe load in pyevolver:
tests/reference/test_dump_roundtrip.py)."""
import io
import os
import re
import subprocess

import pytest

import pyevolver
from conftest import example
from reference import run_reference
from tolerances import LOOSE

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
G_LINE = re.compile(r"^\s*\d+\.\s+(?:area|length):\s*(\S+)\s+energy:\s*(\S+)")
NUMBERS = ('foreach edge ee do printf "RESULT %.15g\\n", ee.length\n'
           'foreach facet ff do printf "RESULT %.15g\\n", ff.area\n'
           'foreach vertex vv do printf "RESULT %.15g %.15g\\n", vv.x, vv.y\n'
           'printf "RESULT %.15g\\n", total_energy\n')

CONF_SOAP = """CONFORMAL_METRIC (1 + x)^2 + y*z
vertices
1 0 0 0 fixed
2 1 0 0 fixed
3 1 1 0.3 fixed
4 0 1 0 fixed
5 0.5 0.4 0.2
edges
1 1 2 fixed
2 2 3 fixed
3 3 4 fixed
4 4 1 fixed
5 1 5
6 2 5
7 3 5
8 4 5
faces
1 1 6 -5
2 2 7 -6
3 3 8 -7
4 4 5 -8
"""

CONF_STRING = """STRING
SPACE_DIMENSION 2
CONFORMAL_METRIC 1 + 1/(x^2 + y^2)
vertices
1 1 0
2 0.2 1.5
3 -2 0
4 0 -1
edges
1 1 2
2 2 3
3 3 4
4 4 1
"""


KLEIN_SOAP = """KLEIN_METRIC
vertices
1 -0.3 -0.3 0 fixed
2 0.5 -0.3 0 fixed
3 0.5 0.4 0.2 fixed
4 -0.3 0.4 0 fixed
5 0.1 0.05 0.3
edges
1 1 2 fixed
2 2 3 fixed
3 3 4 fixed
4 4 1 fixed
5 1 5
6 2 5
7 3 5
8 4 5
faces
1 1 6 -5
2 2 7 -6
3 3 8 -7
4 4 5 -8
"""

KLEIN_STRING = """STRING
SPACE_DIMENSION 2
KLEIN_METRIC
vertices
1 0.5 0.1
2 0.1 0.6
3 -0.7 0.1
4 0.1 -0.4 fixed
edges
1 1 2
2 2 3
3 3 4
4 4 1
"""


def _numbers(lines):
    out = []
    for ln in lines:
        m = G_LINE.match(ln)
        if m:
            out.append(float(m.group(2)))
        elif ln.startswith("RESULT"):
            out.extend(float(v) for v in ln.split()[1:])
    return out


def _ours(path, script):
    out = io.StringIO()
    sess = pyevolver.load(path, out=out, err=io.StringIO())
    sess.run(script)
    return _numbers(out.getvalue().split("\n")), sess


def _compare(evolver, path, script, cwd=None):
    ref = _numbers(run_reference(evolver, path, script, timeout=120, cwd=cwd))
    ours, sess = _ours(path, script)
    assert len(ours) == len(ref) and ref, (len(ours), len(ref))
    for k, (a, b) in enumerate(zip(ours, ref)):
        assert abs(a - b) <= LOOSE * max(abs(a), abs(b), 1.0), (k, a, b)
    return sess


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


@pytest.mark.parametrize("script", ["g 10", "r\ng 10", "r\nr\ng 3", "U\ng 5", "g 5\nl 0.5\ng 5"])
def test_metric_fe(evolver, script):
    _compare(evolver, example("metric.fe"), script + "\n" + NUMBERS)


@pytest.mark.parametrize("script", ["r\ng 12\nr\ng 5", "r\nr\ng 10", "gogo"])
def test_quadm_nonidentity(evolver, script):
    _compare(evolver, os.path.join(DATA, "quadm_curved.fe"), script + "\n" + NUMBERS)


def test_quadm_gogo(evolver):
    _compare(evolver, example("quadm.fe"), "gogo\n" + NUMBERS)


@pytest.mark.parametrize("script", ["", "g 10", "r\ng 8", "g 3\nl 0.3\ng 3"])
def test_conformal_soapfilm(evolver, tmp_path, script):
    path = _write(tmp_path, "cs.fe", CONF_SOAP)
    _compare(evolver, path, script + "\n" + NUMBERS, cwd=str(tmp_path))


@pytest.mark.parametrize("script", ["", "g 10", "r\ng 10"])
def test_conformal_string(evolver, tmp_path, script):
    path = _write(tmp_path, "cst.fe", CONF_STRING)
    _compare(evolver, path, script + "\n" + NUMBERS, cwd=str(tmp_path))


@pytest.mark.parametrize("script", ["", "g 10", "r\ng 10", "r\nr\ng 5\nt 0.05\ng 3",
                                    "r\ng 5\nl 0.2\ng 3"])
@pytest.mark.parametrize("name", ["ks.fe", "kst.fe"])
def test_klein(evolver, tmp_path, name, script):
    """KLEIN_METRIC: lengths arccosh((1 − x·y)/√((1 − |x|²)(1 − |y|²))), areas
    by the hyperbolic L'Huilier formula, as REF to the last digit."""
    words = [ln.split()[0] for ln in script.split("\n") if ln.split()]
    path = _write(tmp_path, name, KLEIN_SOAP if name == "ks.fe" else KLEIN_STRING)
    # after l the soapfilm's element numbering is not REF's (as without a metric):
    # the g lines and the final energy only
    tail = 'printf "RESULT %.15g\\n", total_energy\n' if "l" in words else NUMBERS
    _compare(evolver, path, script + "\n" + tail, cwd=str(tmp_path))


@pytest.mark.parametrize("src", ["metric", "quadm_curved", "conf_soap", "klein"])
def test_our_dump_loads_in_ref(evolver, tmp_path, src):
    path = {"metric": example("metric.fe"),
            "quadm_curved": os.path.join(DATA, "quadm_curved.fe"),
            "conf_soap": _write(tmp_path, "cs.fe", CONF_SOAP),
            "klein": _write(tmp_path, "ks.fe", KLEIN_SOAP)}[src]
    ours, sess = _ours(path, "r\ng 4\n" + 'printf "RESULT %.15g\\n", total_energy\n')
    dmp = str(tmp_path / "ours.dmp")
    sess.run(f'dump "{dmp}"')
    ref = _numbers(run_reference(evolver, dmp, 'printf "RESULT %.15g\\n", total_energy\ng 3\n',
                                 cwd=str(tmp_path)))
    again, _ = _ours(dmp, 'printf "RESULT %.15g\\n", total_energy\ng 3\n')
    assert abs(ref[0] - ours[-1]) <= 1e-12 * abs(ours[-1])
    assert len(ref) == len(again) == 4
    for a, b in zip(again, ref):
        assert abs(a - b) <= LOOSE * max(abs(a), abs(b), 1.0), (a, b)


def test_hessian_of_the_trivial_conformal_metric(evolver, tmp_path):
    """CONFORMAL_METRIC 1 is the Euclidean metric: REF's `hessian` (without
    worker threads: with -p1 its step falls short, docs/differences.md,
    "REF's threaded Hessian") and pyevolver's equal the plain file's step."""
    flat = CONF_SOAP.replace("CONFORMAL_METRIC (1 + x)^2 + y*z\n", "")
    one = _write(tmp_path, "one.fe", "CONFORMAL_METRIC 1\n" + flat)
    plain = _write(tmp_path, "plain.fe", flat)
    script = "r\ng 5\nhessian\n"
    ref_one = _numbers(run_reference(evolver, one, script, cwd=str(tmp_path)))[-1]
    ref_plain = _numbers(run_reference(evolver, plain, script, cwd=str(tmp_path)))[-1]
    ours_one = _ours(one, script)[0][-1]
    assert abs(ref_one - ref_plain) <= 1e-12 * ref_plain
    assert abs(ours_one - ref_plain) <= 1e-12 * ref_plain


def test_hessian_of_a_conformal_metric(evolver, tmp_path):
    """A curved conformal metric: REF's `hessian` step (one thread) and
    pyevolver's agree."""
    path = _write(tmp_path, "cs.fe", CONF_SOAP)
    script = "r\ng 5\nhessian\n"
    ref = _numbers(run_reference(evolver, path, script, cwd=str(tmp_path)))[-1]
    ours = _ours(path, script)[0][-1]
    assert abs(ours - ref) <= 1e-9 * abs(ref)


GENERAL = "METRIC\n(1+x)^2+y*z 0 0\n0 (1+x)^2+y*z 0\n0 0 (1+x)^2+y*z\n"


def test_named_methods_in_a_metric(evolver, tmp_path):
    """REF's named facet_area and edge_length stay Euclidean under a metric;
    metric_facet_area measures in it (here as an ENERGY beside the default
    area: twice the area in the g lines)."""
    quants = ("quantity qa info_only method facet_area global\n"
              "quantity ql info_only method edge_length global\n"
              "quantity mfa energy method metric_facet_area global\n")
    text = CONF_SOAP.replace("CONFORMAL_METRIC (1 + x)^2 + y*z\n", GENERAL + quants)
    path = _write(tmp_path, "nm.fe", text)
    show = ('printf "RESULT %.15g %.15g %.15g %.15g %.15g\\n", total_area, qa.value, ql.value, '
            'mfa.value, sum(edge, length)\n')
    _compare(evolver, path, show + "r\ng 5\n" + show, cwd=str(tmp_path))


def test_metric_edge_length_string(evolver, tmp_path):
    text = open(example("metric.fe")).read().replace(
        "\nvertices", "\nquantity mel info_only method metric_edge_length global\n"
                      "quantity el info_only method edge_length global\n\nvertices", 1)
    path = _write(tmp_path, "mq.fe", text)
    show = 'printf "RESULT %.15g %.15g\\n", mel.value, el.value\n'
    _compare(evolver, path, show + "g 4\n" + show, cwd=str(tmp_path))


def test_metric_methods_need_a_general_metric(evolver, tmp_path):
    text = CONF_SOAP.replace("\nvertices", "\nquantity mfa info_only method metric_facet_area "
                                           "global\n\nvertices", 1)
    path = _write(tmp_path, "bad.fe", text)
    ref = subprocess.run([evolver, "-p1", path], input="print mfa.value\nq\nq\n", capture_output=True,
                         text=True, timeout=60, cwd=str(tmp_path))
    assert "ERROR 1583" in ref.stdout + ref.stderr, ref
    with pytest.raises(pyevolver.errors.PyEvolverError, match="without a general metric"):
        _ours(path, "print mfa.value\n")


def test_gap_energy_in_a_metric(evolver, tmp_path):
    """Gap energy (CONVEX constraints) measures Euclidean edges under a metric,
    as REF: tankex.fe with a conformal metric (its ENERGY integrals, refused
    with a metric, taken out)."""
    text = open(example("tankex.fe")).read()
    text = re.sub(r"energy:[^\n]*\ne1:[^\n]*\ne2:[^\n]*\ne3:[^\n]*\n", "", text)
    at = re.search(r"^\s*vertices", text, re.M | re.I).start()
    text = text[:at] + "\nCONFORMAL_METRIC 1 + 0.1*x^2 + 0.05*y\n" + text[at:]
    path = _write(tmp_path, "tg.fe", text)
    _compare(evolver, path, 'printf "RESULT %.15g\\n", total_energy\ng 5\nr\ng 5\n'
                            'printf "RESULT %.15g\\n", total_energy\n', cwd=str(tmp_path))


STRING_BODY = """STRING
SPACE_DIMENSION 2
CONFORMAL_METRIC 1 + 0.3*x^2
vertices
1 1 0
2 0.2 1.5
3 -1.2 0.1
4 0.1 -1
edges
1 1 2
2 2 3
3 3 4
4 4 1
faces
1 1 2 3 4
bodies
1 1 volume 3
"""


def test_string_body_in_a_metric(evolver, tmp_path):
    """A string-model body keeps its Euclidean area (the constraint) while
    the length is the metric's."""
    path = _write(tmp_path, "sb.fe", STRING_BODY)
    _compare(evolver, path, "g 10\nr\ng 10\n" + NUMBERS +
             'printf "RESULT %.15g\\n", body[1].volume\n', cwd=str(tmp_path))
