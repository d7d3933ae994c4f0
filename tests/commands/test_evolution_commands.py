"""Direct tests of pyevolver.commands.evolution: the handlers of g, m,
optimize, U, G, recalc, convert_to_quantities; messages and energies
against the reference Evolver run live."""
import io
import os

import pytest

from pyevolver import Session
from pyevolver.commands import evolution
from pyevolver.commands.registry import COMMANDS
from pyevolver.errors import CommandError

from reference import run_reference
from tolerances import STEPS

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def lines(text):
    return [l for l in text.split("\n") if l.strip()]


def test_handlers_registered_in_family():
    for word in ("g", "m", "optimize", "bfgs", "newton", "hessian", "hessian_seek", "U", "G",
                 "recalc", "convert_to_quantities"):
        assert COMMANDS[word].family == evolution.FAMILY


MESSAGES = "m 0.2\noptimize 0.5\nU\nU\nG 2\nG 0\nconvert_to_quantities\nconvert_to_quantities\n"


def test_messages_match_reference(evolver):
    ref = lines("\n".join(run_reference(evolver, CUBE, MESSAGES)))
    s = session()
    s.run(MESSAGES)
    assert lines(s.out.getvalue()) == ref
    assert s.settings["scale_limit"] == 0.5 and s.toggles["_fixed_scale"] == 0
    assert s.toggles["conj_grad"] == 0 and s.toggles["gravity"] == 0


def test_g_steps_energy_matches_reference(evolver):
    script = "g 5\nprintf \"RESULT %.17g %.17g\\n\", total_energy, body[1].volume\n" \
             "m 0.1\ng3\nprintf \"RESULT %.17g\\n\", total_energy\n"
    ref = [l.split()[1:] for l in run_reference(evolver, CUBE, "QUIETGO\n" + script)
           if l.startswith("RESULT")]
    e5, v5 = map(float, ref[0])
    e8 = float(ref[1][0])
    s = session()
    s.run("quietgo")
    s.run("g 5")
    assert s.total_energy == pytest.approx(e5, rel=STEPS)
    assert s.value("body[1].volume") == pytest.approx(v5, rel=STEPS)
    s.run("m 0.1; g3")
    assert s.total_energy == pytest.approx(e8, rel=STEPS)
    assert e8 <= e5 < 6.0                     # the cube's area 6 goes down


def test_m_needs_a_value():
    s = session()
    with pytest.raises(CommandError, match="m needs a scale"):
        s.run("m")
