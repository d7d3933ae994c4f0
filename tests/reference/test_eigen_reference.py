"""The eigenvalue commands against evolver-nox-d, run live: ``eigenprobe``
(its counts exactly), ``ritz`` (every eigenvalue within 1e-6),
``eigenprobe(λ, n)`` and ``lanczos`` (the converged value, the nearest
one), ``saddle``, and the warning of ``hessian`` when the Hessian is not
positive definite.

Cases: cube.fe after ``g 10`` (a triple eigenvalue: the translations seen
through normal motion; with ``hessian_normal off`` six zero eigenvalues,
translations and rotations), mound.fe after ``g 10`` (constraint and
volume; with ``hessian_normal off`` a negative and two zero eigenvalues),
cube.fe with ``linear_metric`` (mix 0.5, 0 and 1), catbody.fe grown to volume 8 (two negative eigenvalues: ``hessian`` warns,
``saddle`` moves).
"""
import re
import subprocess

import pytest

from comparison import _same, run_pyevolver
from conftest import example
from reference import run_reference, reference_args
from tolerances import LOOSE

COUNTS = re.compile(r"^Eigencounts:\s+(\d+) <,\s+(\d+) ==,\s+(\d+) > $")
RITZ = re.compile(r"^\s*(\d+)\.\s+(-?\d+\.\d+)$")
LANCZOS = re.compile(r"^(\d+)\s+(-?\d+\.\d+)$")
PROBE = re.compile(r"^(\d+)  ev =\s+(-?\d+\.\d+)$")

CATBODY8 = "u\nbody[1].target := 8\ng 5\nr\ng 5\nV\nV\nr\ng 10\n"


def _blocks(lines):
    """[(counts, [values])] of each Eigencounts line and the ritz values after it."""
    out = []
    for ln in lines:
        m = COUNTS.match(ln)
        if m:
            out.append((tuple(int(x) for x in m.groups()), []))
            continue
        m = RITZ.match(ln)
        if m and out:
            out[-1][1].append(float(m.group(2)))
    return out


def _compare(evolver, name, script, tmp_path):
    ref = run_reference(evolver, example(name), script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example(name), script + "q\n", cwd=str(tmp_path))
    b_ref, b_out = _blocks(ref), _blocks(out)
    assert b_ref and len(b_out) == len(b_ref), (ref, out)
    for (c_ref, v_ref), (c_out, v_out) in zip(b_ref, b_out):
        assert c_out == c_ref, (ref, out)
        assert len(v_out) == len(v_ref), (ref, out)
        for a, b in zip(v_out, v_ref):
            assert abs(a - b) < LOOSE, (v_out, v_ref)
    return ref, out, err


@pytest.mark.parametrize("name,script", [
    ("cube", "g 10\neigenprobe 1\neigenprobe 0\nritz(1,5)\nritz(0,20)\n"
             "hessian_normal off\neigenprobe 0\neigenprobe 1e-9\nritz(-0.01,10)\n"
             # linear_metric: the mix of the star and linear interpolation metrics
             "hessian_normal on\nlinear_metric\nritz(0,5)\neigenprobe 1\n"
             "linear_metric_mix := 0\nritz(0,5)\nlinear_metric_mix := 1\nritz(0,5)\n"
             "hessian_normal off\nritz(0.1,5)\n"),
    ("mound", "g 10\neigenprobe 0\neigenprobe 1\nritz(0,6)\n"
              "hessian_normal off\neigenprobe 0\nritz(-0.1,4)\n"),
])
def test_eigenprobe_and_ritz_match_reference(evolver, tmp_path, name, script):
    _compare(evolver, name, script, tmp_path)


def test_probe_iteration_lanczos_and_last_eigenvalue(evolver, tmp_path):
    """``eigenprobe(λ, n)`` converges (near λ) to REF's eigenvalue and sets
    last_eigenvalue; ``ritz`` sets eigenvalues[]; ``lanczos``'s first value
    (REF: "usually very accurate") is REF's.  No negative eigenvalue:
    ``saddle`` prints REF's "Not a saddle point." line; ``ritz 1``, ``lanczos``
    and ``eigenprobe`` without arguments are refused with REF's syntax lines."""
    script = ("g 10\neigenprobe(0.3,50)\nprint last_eigenvalue\nritz(0,3)\n"
              "print eigenvalues[3]\nlanczos 1\nsaddle\nritz 1\nlanczos\neigenprobe\n")
    ref, out, err = _compare(evolver, "cube", script, tmp_path)
    for lines in (ref, out):
        assert next(x for x in lines if PROBE.match(x)).startswith("0  ev =")
    last = [float(PROBE.match(x).group(2)) for x in (ref, out)
            for x in [[y for y in x if PROBE.match(y)][-1]]]
    assert abs(last[0] - last[1]) < LOOSE
    printed = [[float(y) for y in x if re.fullmatch(r"\s*-?\d+\.\d+", y)] for x in (ref, out)]
    assert len(printed[0]) == len(printed[1]) == 2
    assert all(abs(a - b) < LOOSE for a, b in zip(*printed))
    lz = [[float(LANCZOS.match(y).group(2)) for y in x if LANCZOS.match(y)] for x in (ref, out)]
    assert abs(lz[0][0] - lz[1][0]) < LOOSE
    pick = [x for x in ref if x.startswith("Lowest")]
    mine = [x for x in out if x.startswith("Lowest")]
    assert len(pick) == len(mine) == 1 and mine[0].endswith(". Not a saddle point.")
    assert abs(float(mine[0].split()[2].rstrip(".")) - float(pick[0].split()[2].rstrip("."))) \
        < LOOSE
    proc = subprocess.run(reference_args(evolver, example("cube"), script), input=script + "q\nq\n",
                          capture_output=True, text=True, timeout=120, cwd=str(tmp_path))
    for word in ("RITZ(", "lanczos rexpr", "EIGENPROBE probe_value"):
        line = next(x for x in proc.stderr.split("\n") if word in x)
        assert line.split(": ", 1)[1].strip() in err


def test_hessian_warns_and_saddle_moves_down(evolver, tmp_path):
    """Two negative eigenvalues: ``eigenprobe`` and ``ritz`` as REF;
    ``hessian`` prints REF's warning (to stderr, with the index) and still steps; ``saddle`` reports REF's lowest
    eigenvalue and lowers the energy.  The eigenvalue is double (the shape
    is symmetric), so the direction within its eigenspace (REF: random;
    pyevolver: the force's part in it) and the step are not REF's: the
    decrease must be at least 90% of REF's (measured: 0.0958 against
    0.0928)."""
    script = CATBODY8 + "eigenprobe 0\neigenprobe -0.05\nritz(-1,3)\nhessian\nsaddle\n"
    proc = subprocess.run(reference_args(evolver, example("catbody"), script), input=script + "q\nq\n",
                          capture_output=True, text=True, timeout=120, cwd=str(tmp_path))
    ref, out, err = _compare(evolver, "catbody", script, tmp_path)
    want = "WARNING 1825: Hessian not positive definite. Index: 2\n\n"
    assert want in proc.stderr
    assert want in err

    def parse(lines):
        i = next(k for k, x in enumerate(lines) if x.startswith("Lowest eigenvalue"))
        e0 = float([x for x in lines[:i] if "energy:" in x][-1].split()[4])   # hessian's
        low = float(lines[i].split()[2])
        assert re.fullmatch(r"stepsize -?[\d.e+-]+", lines[i + 1])
        m = re.fullmatch(r"1\. area:\s+(\S+) energy:\s+(\S+) ", lines[i + 2])
        return e0, low, float(m.group(2))
    e0_ref, low_ref, e1_ref = parse(ref)
    e0, low, e1 = parse(out)
    assert abs(e0 - e0_ref) < LOOSE
    assert abs(low - low_ref) < LOOSE and low < 0
    assert e0 - e1 > 0.9 * (e0_ref - e1_ref) > 0


@pytest.mark.slow                                  # (sphere.fe's gap Hessian: 5 s)
def test_where_the_evolver_refuses_the_hessian_we_say_so(evolver, tmp_path):
    """sphere.fe has gap energy: REF refuses its Hessian (ERROR 1604);
    pyevolver goes on and says so once."""
    script = "g 2\neigenprobe 0\nhessian\n"
    proc = subprocess.run(reference_args(evolver, example("sphere"), script),
                          input=script + "q\nq\n",
                          capture_output=True, text=True, timeout=120, cwd=str(tmp_path))
    assert "ERROR 1604" in proc.stdout + proc.stderr
    code, out, err = run_pyevolver(example("sphere"), script + "q\n", cwd=str(tmp_path))
    assert err.count("refuses: ERROR 1604)") == 1
    assert COUNTS.match(next(x for x in out if x.startswith("Eigencounts")))


def test_fixed_volume_with_content_integrals(evolver, tmp_path):
    """column.fe: the body volume with content integrals becomes a global
    quantity; REF without worker threads steps (with -p1 it refuses, ERROR
    3362) and pyevolver's steps print REF's energies."""
    script = "g 2\neigenprobe 0\nhessian\nhessian\nprint total_energy\n"
    ref = run_reference(evolver, example("column.fe"), script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example("column.fe"), script + "q\n", cwd=str(tmp_path))
    assert err == ""
    # after g 2 (its flat line search's scale is round-off) the steps
    def tail(lines):
        lines = [l for l in lines if l.strip() and not l.startswith("Converting to all named")]
        return lines[next(i for i, l in enumerate(lines) if l.startswith("Eigencounts")):]
    assert _same(tail(out), tail(ref), 1e-9), (out, ref)


def test_check_increase_undoes_a_hessian_step(evolver, tmp_path):
    """cube.fe after ``g 2``: the Newton step raises the area; with
    ``check_increase`` REF warns (stderr) and restores, as pyevolver does."""
    script = "g 2\ncheck_increase\nhessian\n"
    proc = subprocess.run(reference_args(evolver, example("cube"), script), input=script + "q\nq\n",
                          capture_output=True, text=True, timeout=120, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example("cube"), script + "q\n", cwd=str(tmp_path))
    want = "WARNING 1596: Hessian move would have raised energy.  Restoring coords.\n\n"
    assert want in proc.stderr and want in err
    ref = run_reference(evolver, example("cube"), script, cwd=str(tmp_path))
    assert [x for x in out if "area:" in x][-1] == [x for x in ref if "area:" in x][-1]
