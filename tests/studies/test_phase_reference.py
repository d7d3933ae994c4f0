"""Branches and transitions of the axisymmetric phase diagram
(pyevolver.studies.phase_reference).

Expected numbers: the published transitions of the spontaneous-curvature
model at c0 = 0 (Seifert, Berndl & Lipowsky, Phys. Rev. A 44, 1182 (1991),
Fig. 8: prolate/oblate at v = 0.652, oblate/stomatocyte at v = 0.592);
issue 27 asks for 0.01.
"""
import numpy as np
import pytest

from pyevolver.studies import phase_reference as pr
from pyevolver.studies.axisymmetric import Helfrich, canham_reference


def test_c0_zero_transitions_match_seifert_berndl_lipowsky():
    grid = [0.575, 0.6, 0.625, 0.65, 0.675]
    br = {b: pr.follow(b, grid) for b in ("prolate", "oblate", "stomatocyte")}
    po = pr.crossing(br["prolate"], br["oblate"])
    os_ = pr.crossing(br["oblate"], br["stomatocyte"])
    assert po is not None and abs(po - 0.652) < 0.01
    assert os_ is not None and abs(os_ - 0.592) < 0.01
    # the branches are the shapes their names say
    assert {p.result.descriptors["type"] for p in br["oblate"]} == {"discocyte"}
    assert {p.result.descriptors["type"] for p in br["stomatocyte"]} == {"stomatocyte"}


def test_continuation_gives_the_direct_solution():
    """A point reached by continuation equals the same point solved from the
    branch's initial shape (where that converges)."""
    pts = pr.follow("prolate", [0.8, 0.85, 0.9])
    direct = canham_reference(0.9, "prolate", n=pr.MODES["prolate"])
    assert [p.v for p in pts] == [0.8, 0.85, 0.9]
    assert abs(pts[-1].W - direct.W) < 1e-9 * direct.W


def test_negative_spontaneous_curvature_favours_the_stomatocyte():
    """c0 < 0 lowers the stomatocyte below the discocyte at larger v (the
    oblate/stomatocyte transition moves up from 0.592)."""
    m = Helfrich(c0=-0.5)
    grid = [0.6, 0.65, 0.7, 0.75]
    ob = pr.follow("oblate", grid, m)
    st = pr.follow("stomatocyte", grid, m)
    v = pr.crossing(ob, st, m)
    assert v is not None and v > 0.62


def test_unknown_branch_is_refused():
    with pytest.raises(ValueError, match="unknown branch"):
        pr.follow("torus", [0.8])


def test_cli_prints_branches_and_transitions(capsys):
    assert pr.main(["--vmin", "0.8", "--vmax", "0.85", "--step", "0.05"]) == 0
    out = capsys.readouterr().out
    assert "prolate,0.8000," in out and "transition prolate/oblate" in out
