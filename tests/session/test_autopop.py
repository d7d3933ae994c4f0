"""pyevolver.session.popping: autopop and autochop during ``g``, against
the reference Evolver run live."""
import os
import re
import subprocess

import pytest

import pyevolver
from pyevolver.session import popping

JUNCTION = """STRING
SPACE_DIMENSION 2
scale 0.1 fixed
vertices
1 0 0
2 1 0 fixed
3 0 1 fixed
4 -1 0 fixed
edges
1 1 2
2 1 3
3 1 4
"""


def _ref(exe, path, cmds):
    script = "\n".join(cmds + ["q", "q"]) + "\n"
    return subprocess.run([exe, "-p1", path], input=script, capture_output=True, text=True,
                          timeout=60, cwd=os.path.dirname(path)).stdout


@pytest.mark.parametrize("L", [1.0, 1.012, 1.0149, 1.0151, 1.03])
def test_autochop_predicted_length(tmp_path, evolver, L):
    # the two growing edges are 1.00499 after the move; REF chops them up to
    # the first-order prediction 1.014938 of the next move
    f = tmp_path / "j.fe"
    f.write_text(JUNCTION)
    cmds = ["autochop on", f"autochop_length := {L}", "g 2"]
    out = _ref(evolver, str(f), cmds)
    sess = pyevolver.load(str(f))
    sess.run("autochop on")
    sess.run(f"autochop_length := {L}")
    res = sess.g(2)
    ref_chops = re.findall(r"Autochopped (\d+) edges", out)
    ours = [w for r in res for w in r.warnings if w.startswith("Autochopped")]
    assert [f"Autochopped {n} edges." for n in ref_chops] == ours
    e = float(re.findall(r"length:\s*(\S+)", out)[-1])
    assert sess.total_energy == pytest.approx(e, rel=1e-12)


def test_autopop_refused_in_soapfilm(tmp_path):
    sess = pyevolver.load("/usr/share/doc/evolver/examples/cube.fe") \
        if os.path.exists("/usr/share/doc/evolver/examples/cube.fe") else None
    if sess is None:
        pytest.skip("examples not installed")
    sess.toggles["autopop"] = 1
    with pytest.raises(pyevolver.errors.UnsupportedError, match="soapfilm"):
        popping.check_supported(sess)
    with pytest.raises(pyevolver.errors.UnsupportedError, match="soapfilm"):
        sess.g(1)


@pytest.mark.slow
def test_100grain_g10_as_ref(evolver):
    path = "/usr/share/doc/evolver/examples/100grain.fe"
    out = _ref(evolver, path, ["g 10"])
    sess = pyevolver.load(path)
    res = sess.g(10)
    ref = [float(x) for x in re.findall(r"length:\s*(\S+)", out)]
    assert [r.energy for r in res] == pytest.approx(ref, rel=1e-10)


def _lines(text):
    return [(m.group(0)) for m in re.finditer(r"Autochopped \d+ edges|Autopopped \d+ edges, \d+ vertices",
                                               text)], \
        [float(x) for x in re.findall(r"energy:\s*(\S+)", text)]


def test_autochop_soapfilm_mound_as_ref(evolver):
    path = "/usr/share/doc/evolver/examples/mound.fe"
    cmds = ["autochop on", "autochop_length := 0.6", "g 4"]
    ref_msgs, ref_e = _lines(_ref(evolver, path, cmds))
    sess = pyevolver.load(path)
    for c in cmds[:2]:
        sess.run(c)
    res = sess.g(4)
    ours = [w.rstrip(".") for r in res for w in r.warnings if w.startswith("Auto")]
    assert ours == ref_msgs
    assert [r.energy for r in res] == pytest.approx(ref_e, rel=1e-10)


def test_r_halves_autochop_length(evolver):
    path = "/usr/share/doc/evolver/examples/cube.fe"
    out = _ref(evolver, path, ["autochop_length := 0.5", "r", "print autochop_length"])
    ref = float(re.findall(r"^\s*([0-9.]+)\s*$", out, re.M)[-1])
    sess = pyevolver.load(path)
    sess.run("autochop_length := 0.5")
    sess.run("r")
    assert sess.settings["autochop_length"] == ref == 0.25


def test_100grain_r_g4_as_ref(evolver):
    # after r: autopop deletes edges (junctions stay, midpoint vertices go),
    # autochop's choice made before the deletions
    path = "/usr/share/doc/evolver/examples/100grain.fe"
    ref_msgs, ref_e = _lines(_ref(evolver, path, ["r", "g 4"]))
    sess = pyevolver.load(path)
    sess.run("r")
    res = sess.g(4)
    ours = [w.rstrip(".") for r in res for w in r.warnings if w.startswith("Auto")]
    assert ours == ref_msgs
    assert [r.energy for r in res] == pytest.approx(ref_e, rel=1e-10)
