"""The third-party corpus (``../shared/corpus``, see its README.md): each
datafile runs the corpus SCRIPT.txt in pyevolver, in the corpus files folder
as the reference transcripts were made, and every printed value must agree
with ``reference/<name>.out`` (the Evolver's own transcript) within 1e-6
relative.

The four generated elastic sheets (shengdie) are compared like the others:
their read sections and companion scripts run (``exec``, ``set vv gbend``,
``equiangulate edge where ...``, curvature energies in the torus model,
conj_grad with an OPTIMIZING_PARAMETER, boundaries across the wrap).  The
Evolver dumps (``.dmp``) are compared like the datafiles.

Skipped only when the corpus folder is absent (``PYEVOLVER_CORPUS`` names
it when the checkout is elsewhere).  The corpus files are never copied into
the repository.
"""
from __future__ import annotations

import csv
import io
import os
import re

import numpy as np
import pytest
from tolerances import LOOSE

from pyevolver.cli import main as cli
from pyevolver.commands import interpreter as I
from pyevolver.session.core import Session

_HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
_CANDIDATES = [os.path.join(_HERE, "..", "..", "shared", "corpus"),
               os.environ.get("PYEVOLVER_CORPUS", "")]
CORPUS = next((os.path.normpath(c) for c in _CANDIDATES
               if c and os.path.isfile(os.path.join(c, "INDEX.tsv"))), None)

# values printed by SCRIPT.txt (one per line, after a 'STAGE name' line)
_VALUE = re.compile(r"(?:Enter command: )?(total_energy|total_area|vertex_count|edge_count|"
                    r"facet_count|body_count) (\S+)")


def _rows():
    if CORPUS is None:
        return []
    with open(os.path.join(CORPUS, "INDEX.tsv"), newline="") as fh:
        rows = list(csv.reader(fh, delimiter="\t"))[1:]
    return [(r[0], r[4]) for r in rows if r[4] != "companion"]


def _params(sheets=None):
    """All datafiles; the elastic sheets (60-80 s each with ``r; g 5``) are
    marked slow, their load and ``g 5`` stages run by default
    (``sheets=True``: only the sheets, not marked)."""
    out = []
    for name, kind in _rows():
        if sheets and kind != "elastic-sheet":
            continue
        marks = [pytest.mark.slow] if kind == "elastic-sheet" and not sheets else []
        out.append(pytest.param(name, kind, id=name.split("__")[-1], marks=marks))
    if not out:
        out.append(pytest.param(None, None, id="corpus-absent",
                                marks=pytest.mark.skip(reason="no third-party corpus")))
    return out


def printed_values(text):
    """``{(stage, name): value}`` of the values the corpus script prints."""
    got = {}
    stage = None
    for line in text.splitlines():
        m = re.search(r"STAGE (\w+)", line)
        if m:
            stage = m.group(1)
            continue
        m = _VALUE.match(line)
        if m and stage:
            got[(stage, m.group(1))] = float(m.group(2))
    return got


def run_script(name, monkeypatch, first_stages=False):
    """Load ``name`` in the corpus files folder and feed SCRIPT.txt as the
    Evolver's standard input (with ``first_stages`` only up to its ``r; g 5``);
    returns what was printed and the messages."""
    with open(os.path.join(CORPUS, "SCRIPT.txt"), encoding="latin-1") as fh:
        script = fh.read()
    if first_stages:
        script = script[:script.index("r; g 5")] + "q\nq\n"
    monkeypatch.chdir(os.path.join(CORPUS, "files"))
    out, err = io.StringIO(), io.StringIO()
    with np.errstate(all="ignore"):
        ses = Session.load(name, out=out, err=err)
        ses.time_limit = 120
        try:
            cli.repl(ses, stdin=io.StringIO(script))
        except I.Quit:
            pass
    return out.getvalue(), err.getvalue()


@pytest.mark.parametrize("name,kind", _params())
def test_corpus_datafile(name, kind, monkeypatch):
    _compare(name, monkeypatch, False)


@pytest.mark.parametrize("name,kind", _params(sheets=True))
def test_corpus_elastic_sheet_first_stages(name, kind, monkeypatch):
    """The default run's version of the slow sheets: load and ``g 5``
    (read sections, exec, set-quantity, torus curvature, conj_grad with an
    optimizing parameter) against the same transcripts."""
    _compare(name, monkeypatch, True)


def _compare(name, monkeypatch, first_stages):
    with open(os.path.join(CORPUS, "reference", name + ".out"), encoding="latin-1") as fh:
        ref = printed_values(fh.read())
    assert ref, "the reference transcript has no values"
    if first_stages:
        ref = {k: v for k, v in ref.items() if k[0] != "rg5"}
    text, err = run_script(name, monkeypatch, first_stages)
    got = printed_values(text)
    bad = [(k, v, got.get(k)) for k, v in ref.items()
           if got.get(k) is None or abs(got[k] - v) > LOOSE * max(1.0, abs(v))]
    blockers = [ln for ln in err.splitlines()
                if "not supported in pyevolver" in ln or "syntax error" in ln]
    assert not bad, (f"{len(bad)} values differ from the Evolver's, first: {bad[:3]}; "
                     f"messages: {blockers[:3]}")
