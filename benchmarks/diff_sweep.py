"""Differential sweep: pyevolver against the reference Evolver (evolver-nox-d).

Not a test: runs every (datafile, command sequence) pair through both
programs and prints a table and a count per class.

    PYTHONPATH=. python benchmarks/diff_sweep.py [--files PAT] [--seqs NAMES] [--jobs N]
                                                 [--json OUT] [--all]

For each case a script is written with a start marker, the sequence (one
command per line) and a tail that prints ``total_energy`` and the element
counts with 17 digits.  Both programs run it with ``-f SCRIPT FILE`` from the
datafile's directory, stdin from /dev/null, under a timeout.  Compared:

- the energies of the ``g`` lines (``N. area: A energy: E scale: s``), the
  scale column ignored;
- the final ``total_energy`` (the tail);
- vertex / edge / facet / body counts (the tail);
- for the query sequences (``v``, ``list``, ``print``), every number in the
  printed lines.

Classes: ``match`` (max relative difference <= 1e-6), ``small`` (<= 1e-4),
``big``, ``py-refuses`` (pyevolver's "not supported in pyevolver: NAME"),
``py-error`` (pyevolver printed an error message the reference did not),
``py-trace`` (a Python traceback: always a bug), ``py-timeout``,
``ref-error`` (the reference printed ERROR or did not reach the tail; a
reference error ends its ``-f`` script), ``both-error``.  A case that
differs is ``roundoff`` when, after the last prefix where the two states
agree, REF from pyevolver's dump prints pyevolver's numbers or pyevolver
from REF's (full-precision) dump prints REF's, and ``ill-posed`` when REF
disagrees with itself there (from its own dump, or under the 1e-15 change
of its input between a 15-digit and a 17-digit dump): ``_stepwise``,
``_mirror``.
"""
import argparse
import concurrent.futures as cf
import fnmatch
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
EXAMPLES = "/usr/share/doc/evolver/examples"
SHARED = "/work/shared/reference-checks/files"

#: (name, commands, kind); kind "evolve" compares g lines + tail, "query" also
#: every printed number.
SEQUENCES = [
    ("g10", ["g 10"], "evolve"),
    ("r_g10", ["r", "g 10"], "evolve"),
    ("g5_r_u_V_g5", ["g 5", "r", "u", "V", "g 5"], "evolve"),
    ("g5_hessian", ["g 5", "hessian"], "evolve"),
    ("g5_t_g5", ["g 5", "t 0.1", "g 5"], "evolve"),
    ("g5_K_g5", ["g 5", "K 0.2", "g 5"], "evolve"),
    ("g5_w", ["g 5", "w 0.001", "g 5"], "evolve"),
    ("g5_l_g5", ["g 5", "l 0.5", "g 5"], "evolve"),
    ("g5_n_g5", ["g 5", "n 0.5", "g 5"], "evolve"),
    ("U_g5", ["U", "g 5"], "evolve"),
    ("m_g5", ["m 0.05", "g 5"], "evolve"),
    ("r_r_g3", ["r", "r", "g 3"], "evolve"),
    ("g5_o_g5", ["g 5", "o", "g 5"], "evolve"),
    ("list_v", ["list vertices where id < 5"], "query"),
    ("v", ["v"], "query"),
    ("print", ["print total_energy", "print total_area", "print vertex_count"], "query"),
    ("sums", ['printf "%.15g %.15g\\n", sum(vertex, x), sum(facet, area)',
              'printf "%.15g\\n", max(edge, length)'], "query"),
]

TAIL = ['printf "DS_E %.17g\\n", total_energy',
        'printf "DS_C %d %d %d %d\\n", vertex_count, edge_count, facet_count, body_count']

#: the largest relative difference that counts as agreeing (issue 23: 1e-6)
MATCH = 1e-6

G_LINE = re.compile(r"^\s*\d+\.\s+(?:area|length):\s*(\S+)\s+energy:\s*(\S+)")
NUM = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def datafiles(include_all=False):
    files = sorted(glob.glob(os.path.join(EXAMPLES, "*.fe")))
    files += sorted(glob.glob(os.path.join(SHARED, "*.fe")))
    files += sorted(glob.glob(os.path.join(REPO, "datafiles", "*.fe")))
    paper = sorted(glob.glob(os.path.join(REPO, "datafiles", "paper", "*.fe")))
    if not include_all:                     # the small paper meshes only
        paper = [p for p in paper if "5x9" in p or "10x16_offset_normal.fe" in p
                 or "vesicle_prolate_perp" in p]
    seen, out = set(), []
    for f in files + paper:                 # datafiles/cube.fe is the example's copy
        with open(f, "rb") as fh:
            key = fh.read()
        if key not in seen:
            seen.add(key)
            out.append(f)
    return out


def gogo_sequences(fe):
    """The ``gogoN := { ... }`` commands the datafile's read section defines."""
    with open(fe, errors="replace") as f:
        names = re.findall(r"^\s*(gogo\d*)\s*:=\s*\{", f.read(), re.M)
    return [(n, [n], "evolve") for n in dict.fromkeys(names)]


def run(cmd, cwd, timeout, env=None, merge=False):
    try:
        p = subprocess.run(cmd, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT if merge else subprocess.PIPE,
                           text=True, timeout=timeout, env=env, errors="replace")
        return p.stdout, p.stderr, False
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        return out, "", True


def parse(stdout, ref):
    """Lines after the start marker: g energies, tail values, other numbers."""
    lines = stdout.split("\n")
    try:
        start = next(i for i, l in enumerate(lines) if l.strip() == "DS_BEGIN")
    except StopIteration:
        return None
    g, other, energy, counts, error = [], [], None, None, False
    for ln in lines[start + 1:]:
        if ref and (ln.startswith("Enter command:") or ln.startswith("more>")):
            continue
        if ln.startswith("DS_STEP ") or "WARNING" in ln or ln.startswith("Total difference"):
            continue
        if "ERROR" in ln:
            error = True
        m = G_LINE.match(ln)
        if m:
            g.append(float(m.group(2)))
        elif ln.startswith("DS_E "):
            tok = ln.split()[1]
            energy = float("nan") if "nan" in tok.lower() else float(tok)
        elif ln.startswith("DS_C "):
            counts = [int(t) for t in ln.split()[1:]]
        else:
            other.extend(float(t) for t in NUM.findall(ln))
    return {"g": g, "other": other, "energy": energy, "counts": counts, "error": error}


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b), 1e-12)


def compare(p, r, kind):
    """Worst relative difference and a short note."""
    notes, worst = [], 0.0
    if len(p["g"]) != len(r["g"]):
        notes.append(f"g lines {len(p['g'])} vs {len(r['g'])}")
        worst = float("inf")
    for k, (a, b) in enumerate(zip(p["g"], r["g"])):
        d = rel(a, b)
        if d > worst:
            worst = d
    if p["energy"] is None or r["energy"] is None:
        notes.append("no energy")
        worst = float("inf")
    else:
        worst = max(worst, rel(p["energy"], r["energy"]))
    if p["counts"] != r["counts"]:
        notes.append(f"counts {p['counts']} vs {r['counts']}")
        worst = float("inf")
    if kind == "query":
        if len(p["other"]) != len(r["other"]):
            notes.append(f"{len(p['other'])} vs {len(r['other'])} numbers")
            worst = float("inf")
        else:
            for a, b in zip(p["other"], r["other"]):
                worst = max(worst, rel(a, b))
    return worst, "; ".join(notes)


def _script(path, cmds):
    """The case's command file: a start marker, a step marker before each
    command (REF ends a ``-f`` script at its first error, so the last marker
    it printed names the failing command) and the tail."""
    body = ['printf "DS_BEGIN\\n"']
    for k, c in enumerate(cmds):
        body += [f'printf "DS_STEP {k}\\n"', c]
    body += [f'printf "DS_STEP {len(cmds)}\\n"'] + TAIL
    with open(path, "w") as f:
        f.write("\n".join(body) + "\n")


def _failing_step(text, ref, script, fe):
    """Index of the command that failed (-1: loading; None: none failed) and
    the first error line.  REF: an ``ERROR`` line, or no tail at all (a crash
    or an error at load).  pyevolver (stdout and stderr merged, unbuffered):
    its error lines start with the script's or the datafile's path, or are a
    traceback's."""
    step, first = -1, None
    started = False
    for ln in text.split("\n"):
        s = ln.strip()
        if s == "DS_BEGIN":
            started = True
            continue
        if s.startswith("DS_STEP "):
            step = int(s.split()[1])
            continue
        if ref:
            bad = "ERROR" in ln
        else:
            bad = (ln.startswith(script + ":") or ln.startswith(fe + ":")
                   or ln.startswith(os.path.basename(fe) + ":") or "Traceback" in ln)
            if bad and "WARNING" in ln:
                bad = False
        if bad:
            return (step if started else -1), ln.strip()[:160]
    if ref and "DS_E " not in text:
        return (step if started else -1), "no tail (crash, timeout or error at load)"
    return None, None


#: Hessian commands: REF assembles their matrix wrongly with worker threads
#: (with -p1 a method quantity's matrix loses the terms between vertices and
#: FIXED global quantities stop with ERROR 3362); without -p it is exact, so
#: a script using them runs REF single-threaded (docs/differences.md).
_HESSIAN = re.compile(r"\b(hessian\w*|saddle|ritz|eigenprobe|lanczos)\b", re.I)


def _uses_hessian(script_path):
    with open(script_path, encoding="utf-8", errors="replace") as f:
        return bool(_HESSIAN.search(f.read()))


def ref_cmd(script_path, fe, threads=None):
    """REF's command line for ``script_path`` on ``fe``: ``-p1`` (bit-for-bit
    repeatable) unless the script uses a Hessian command (``threads=True``
    forces ``-p1``)."""
    p1 = threads if threads is not None else not _uses_hessian(script_path)
    return ["evolver-nox-d"] + (["-p1"] if p1 else []) + ["-f", script_path, fe]


def _as_threaded_ref(fe, script, timeout, kind, p, res):
    """REF's Hessian depends on its thread mode (docs/differences.md, "REF's
    threaded Hessian"): a Hessian case that differs from single-threaded
    REF is a match when pyevolver prints what REF with ``-p1`` prints."""
    if res["cls"] not in ("small", "big") or p is None or not _uses_hessian(script):
        return
    rout, _, rt = run(ref_cmd(script, fe, threads=True), os.path.dirname(fe), timeout,
                      merge=True)
    r1 = parse(rout, True)
    if rt or r1 is None or r1["energy"] is None:
        return
    worst1, _ = compare(p, r1, kind)
    if worst1 <= MATCH:
        res["note"] = (f"as REF -p1 (single-threaded REF differs by {res['worst']:.2e})")
        res["cls"], res["worst"] = "match", worst1
        res.pop("py", None), res.pop("ref", None)


def _both(fe, script, timeout, tree, cwd=None):
    env = dict(os.environ, PYTHONPATH=tree, PYTHONUNBUFFERED="1")
    cwd = cwd or os.path.dirname(fe)
    pout, perr, ptime = run([sys.executable, "-m", "pyevolver", "-f", script, fe], cwd,
                            timeout, env, merge=True)
    rout, rerr, rtime = run(ref_cmd(script, fe), cwd, timeout, merge=True)
    return (pout, ptime), (rout, rtime)


def one_case(fe, seq, timeout, tree=REPO, stepwise=True):
    """Run one (datafile, sequence) case in both programs and classify it.

    Classes: ``match`` (every compared number within :data:`MATCH`),
    ``roundoff`` (the end-to-end numbers differ, but by round-off that REF
    itself amplifies: :func:`_stepwise`), ``small``/``big`` (differ),
    ``py-refuses`` (pyevolver's "not supported in pyevolver: NAME" at a
    command REF runs), ``both-error`` (both fail at the same command),
    ``ref-error`` (REF fails, pyevolver does not), ``py-error``,
    ``py-trace`` (a traceback: always a bug), ``py-timeout``.
    """
    name, cmds, kind = seq
    res = {"file": os.path.relpath(fe, "/"), "seq": name, "worst": None, "note": ""}
    with tempfile.TemporaryDirectory(prefix="dsweep") as tmp:
        script = os.path.join(tmp, "s.cmd")
        _script(script, cmds)
        (pout, ptime), (rout, rtime) = _both(fe, script, timeout, tree)
        pstep, perr = _failing_step(pout, False, script, fe)
        rstep, rerr = _failing_step(rout, True, script, fe)
        if rtime:
            rstep, rerr = (rstep if rstep is not None else len(cmds)), "timeout"
        p, r = parse(pout, False), parse(rout, True)
        if "Traceback" in pout:
            res["cls"] = "py-trace"
            res["note"] = [l for l in pout.split("\n") if l.strip()][-1][:150]
        elif ptime:
            res["cls"] = "py-timeout"
        elif pstep is not None and "not supported in pyevolver" in (perr or "") and (
                rstep is None or pstep < rstep):
            res["cls"] = "py-refuses"
            res["note"] = perr[perr.index("not supported in pyevolver") + 27:][:150]
        elif rstep is not None:
            if pstep == rstep:
                res["cls"] = "both-error"
                res["note"] = f"step {rstep}: REF {rerr} | ours {perr}"[:200]
            else:
                res["cls"] = "ref-error" if pstep is None or pstep > rstep else "py-error"
                res["note"] = f"REF fails at step {rstep} ({rerr}); ours at {pstep} ({perr})"[:200]
            if res["cls"] in ("both-error", "ref-error") and p and r:
                # the g lines REF printed before its error, ours the same
                k = len(r["g"])
                if len(p["g"]) < k or any(
                        rel(a, b) > MATCH for a, b in zip(p["g"][:k], r["g"])):
                    res["cls"] = "big"
                    res["note"] = "g lines before the common error differ"
        elif pstep is not None or p is None or p["energy"] is None or p["energy"] != p["energy"]:
            res["cls"] = "py-error"
            res["note"] = f"step {pstep}: {perr}"[:150]
        else:
            worst, note = compare(p, r, kind)
            res["worst"], res["note"] = worst, note
            res["cls"] = "match" if worst <= MATCH else "small" if worst <= 1e-4 else "big"
            if res["cls"] != "match":
                res["py"] = {"g": p["g"][-3:], "E": p["energy"], "C": p["counts"]}
                res["ref"] = {"g": r["g"][-3:], "E": r["energy"], "C": r["counts"]}
                if stepwise and len(cmds) > 1:
                    ok, where = _stepwise(fe, seq, timeout, tree, tmp)
                    if ok:
                        res["cls"] = "roundoff"
                        res["note"] = where
                    else:
                        cls, why = _mirror(fe, seq, timeout, tree, tmp, r)
                        if not cls:
                            cls, why = _mirror_split(fe, seq, timeout, tree, tmp, r) or (cls, why)
                        if cls:
                            res["cls"], res["note"] = cls, why
                        else:
                            res["note"] = (res["note"] + "; " + where + "; " + why).strip("; ")
            _as_threaded_ref(fe, script, timeout, kind, p, res)
    return res


COORDS = 'foreach vertex vv do printf "DS_X %d %.17g %.17g %.17g\\n", vv.id, vv.x, vv.y, vv.z'


def _coords(text):
    out = {}
    for ln in text.split("\n"):
        if ln.startswith("DS_X "):
            t = ln.split()
            out[int(t[1])] = [float(v) for v in t[2:]]
    return out


def _stepwise(fe, seq, timeout, tree, tmp):
    """Is the end-to-end difference round-off that REF itself amplifies?

    For a split point k (1 <= k < n): the state after the first k commands
    agrees in the two programs to 1e-8 in every vertex coordinate (relative
    to the largest), and REF, continued from pyevolver's ``dump`` of that
    state, prints pyevolver's numbers for the remaining commands within
    :data:`MATCH`.  (cube.fe ``g 5; l 0.5; g 5``: after ``g 5`` the
    converged cube differs by 2e-10 and so does the scale REF's flat line
    search keeps — 0.0417 against 0 —; from our dump REF prints our lines
    to the last digit.)  Hidden state a dump re-derives (facet and ring
    orders) cannot pass: REF from our dump would then print its own numbers.
    Returns (found, a note)."""
    name, cmds, kind = seq
    env = dict(os.environ, PYTHONPATH=tree, PYTHONUNBUFFERED="1")
    cwd = os.path.dirname(fe)
    for k in range(1, len(cmds)):
        dmp = os.path.join(tmp, f"ours{k}.dmp")
        pre = os.path.join(tmp, f"pre{k}.cmd")
        with open(pre, "w") as f:
            f.write("\n".join(cmds[:k] + [COORDS, f'dump "{dmp}"']) + "\n")
        pout, _, pt = run([sys.executable, "-m", "pyevolver", "-f", pre, fe], cwd, timeout, env,
                          merge=True)
        rpre = os.path.join(tmp, f"rpre{k}.cmd")
        with open(rpre, "w") as f:
            f.write("\n".join(cmds[:k] + [COORDS]) + "\n")
        rout, _, rt = run(ref_cmd(rpre, fe), cwd, timeout, merge=True)
        a, b = _coords(pout), _coords(rout)
        if pt or rt or not a or a.keys() != b.keys() or not os.path.exists(dmp):
            continue
        A = np.array([a[i] for i in sorted(a)])
        B = np.array([b[i] for i in sorted(b)])
        scale = max(np.abs(B).max(), 1e-300)
        if not np.all(np.isfinite(A)) or np.abs(A - B).max() > 1e-8 * scale:
            continue
        # the rest from our dump: REF against pyevolver's own continuation
        rest = os.path.join(tmp, f"rest{k}.cmd")
        _script(rest, cmds[k:])
        full = os.path.join(tmp, "s.cmd")
        (p_full, _), _ = _both(fe, full, timeout, tree)
        rout2, _, rt2 = run(ref_cmd(rest, dmp), cwd, timeout, merge=True)
        p, r = parse(p_full, False), parse(rout2, True)
        if rt2 or p is None or r is None or p["energy"] is None or r["energy"] is None:
            continue
        # our g lines of the remaining commands are the last ones
        n_rest = len(r["g"])
        if n_rest > len(p["g"]):
            continue
        p_rest = dict(p, g=p["g"][len(p["g"]) - n_rest:])
        worst, note = compare(p_rest, r, "evolve")
        if worst <= MATCH:
            return True, (f"after step {k} ({cmds[k - 1]}) the states agree to "
                          f"{np.abs(A - B).max() / scale:.1e} and REF from our dump prints our "
                          f"numbers ({worst:.1e}): amplified round-off")
    return False, "no split point explains it (not round-off)"


def _sdim_coords(text):
    """REF's vertex coordinates with 17 digits, as strings (DS_X lines)."""
    out = {}
    for ln in text.split("\n"):
        t = ln.split()
        if len(t) > 2 and t[0] == "DS_X" and t[1].isdigit():
            out[int(t[1])] = t[2:]
    return out


def full_precision_dump(dump_text, coords, sdim):
    """REF's ``dump`` writes coordinates with 15 significant digits: put
    back the 17-digit ones REF printed (``DS_X id x y z``) in the vertices
    section (a dump keeps the live ids).  Vertices given by boundary
    parameters keep the dump's text.  Returns (text, number patched)."""
    out, sect, n = [], None, 0
    for ln in dump_text.split("\n"):
        s = ln.strip()
        head = s.split()[0].lower() if s else ""
        if head in ("vertices", "edges", "faces", "facets", "bodies", "read"):
            sect = head
        elif sect == "vertices" and s[:1].isdigit():
            t = ln.split()
            vid = int(t[0])
            if vid in coords and "boundary" not in ln.lower() and len(t) > sdim:
                ln = " ".join([t[0]] + coords[vid][:sdim] + t[1 + sdim:])
                n += 1
        out.append(ln)
    return "\n".join(out), n


def _sdim(fe):
    with open(fe, errors="replace") as f:
        m = re.search(r"^\s*space_dimension\s+(\d)", f.read(), re.M | re.I)
    return int(m.group(1)) if m else 3


def _rest_of(full, n_rest):
    """The part of a parsed run that belongs to its last commands."""
    if n_rest > len(full["g"]):
        return None
    return dict(full, g=full["g"][len(full["g"]) - n_rest:])


def _mirror(fe, seq, timeout, tree, tmp, r_full):
    """The mirror of :func:`_stepwise`: at a split point k where the states
    agree to 1e-8, REF dumps its state (coordinates put back to 17 digits:
    :func:`full_precision_dump`) and both programs run the rest from that
    dump.  ``roundoff`` when pyevolver from REF's dump prints REF's own
    numbers (those of REF's uninterrupted run); ``ill-posed`` when REF from
    its own dump no longer prints them (REF disagrees with itself by more
    than :data:`MATCH`: its next decision turns on state the dump does not
    keep, e.g. the order of a vertex's facets, or on a sign at round-off
    level) and pyevolver from the same dump prints what REF prints from it,
    or when REF's result changes beyond :data:`MATCH` under the 1e-15 change
    of its input between the dump's 15-digit and 17-digit coordinates.
    Only the last split point where the states agree is judged (a later
    command's own difference is not excused by an earlier ill-posed one).
    Returns (class or None, a note)."""
    name, cmds, kind = seq
    env = dict(os.environ, PYTHONPATH=tree, PYTHONUNBUFFERED="1")
    cwd = os.path.dirname(fe)
    sdim = _sdim(fe)
    coords = COORDS if sdim == 3 else (
        'foreach vertex vv do printf "DS_X %d %.17g %.17g\\n", vv.id, vv.x, vv.y')
    for k in range(len(cmds) - 1, 0, -1):
        rdmp = os.path.join(tmp, f"ref{k}.dmp")
        rpre = os.path.join(tmp, f"mref{k}.cmd")
        with open(rpre, "w") as f:
            f.write("\n".join(cmds[:k] + [coords, f'dump "{rdmp}"']) + "\n")
        rout, _, rt = run(ref_cmd(rpre, fe), cwd, timeout, merge=True)
        ppre = os.path.join(tmp, f"mpy{k}.cmd")
        with open(ppre, "w") as f:
            f.write("\n".join(cmds[:k] + [coords]) + "\n")
        pout, _, pt = run([sys.executable, "-m", "pyevolver", "-f", ppre, fe], cwd, timeout, env,
                          merge=True)
        a, b = _coords(pout), _coords(rout)
        if pt or rt or not a or a.keys() != b.keys() or not os.path.exists(rdmp):
            continue
        A = np.array([a[i] for i in sorted(a)])
        B = np.array([b[i] for i in sorted(b)])
        scale = max(np.abs(B).max(), 1e-300)
        agree = np.abs(A - B).max() / scale if np.all(np.isfinite(A)) else np.inf
        if agree > 1e-8:
            continue
        with open(rdmp, errors="replace") as f:
            text15 = f.read()
        text, npatched = full_precision_dump(text15, _sdim_coords(rout), sdim)
        if npatched != len(b):
            return None, f"after step {k}, the last where the states agree, nothing explains it"
        rdmp15 = os.path.join(tmp, f"ref{k}_15.dmp")
        with open(rdmp, "w") as f:
            f.write(text)
        with open(rdmp15, "w") as f:
            f.write(text15)
        rest = os.path.join(tmp, f"mrest{k}.cmd")
        _script(rest, cmds[k:])
        p_out, _, p_t = run([sys.executable, "-m", "pyevolver", "-f", rest, rdmp], cwd, timeout,
                            env, merge=True)
        r_out, _, r_t = run(ref_cmd(rest, rdmp), cwd, timeout, merge=True)
        p, r = parse(p_out, False), parse(r_out, True)
        if p_t or r_t or p is None or r is None or p["energy"] is None or r["energy"] is None:
            return None, f"after step {k}, the last where the states agree, nothing explains it"
        ref_own = _rest_of(r_full, len(r["g"]))
        if ref_own is not None:
            w_own, _ = compare(p, ref_own, "evolve")
            if w_own <= MATCH:
                return "roundoff", (f"after step {k} ({cmds[k - 1]}) the states agree to "
                                    f"{agree:.1e} and pyevolver from REF's dump prints REF's "
                                    f"numbers ({w_own:.1e}): amplified round-off")
        w_self = compare(r, ref_own, "evolve")[0] if ref_own is not None else float("inf")
        w_same, _ = compare(p, r, "evolve")
        if w_self > MATCH and w_same <= MATCH:
            return "ill-posed", (f"after step {k} ({cmds[k - 1]}) the states agree to "
                                 f"{agree:.1e}; REF from its own dump (17-digit coordinates) "
                                 f"differs from its uninterrupted run by {w_self:.1e}, "
                                 f"pyevolver from that dump prints REF's numbers ({w_same:.1e}): "
                                 f"REF disagrees with itself")
        # REF's result under a 1e-15 change of its input: its dump's own
        # 15-digit coordinates against the 17-digit ones
        r15_out, _, r15_t = run(ref_cmd(rest, rdmp15), cwd, timeout, merge=True)
        r15 = parse(r15_out, True)
        if r15_t or r15 is None or r15["energy"] is None:
            return None, f"after step {k}, the last where the states agree, nothing explains it"
        w_pert, _ = compare(r15, r, "evolve")
        if w_pert > MATCH:
            return "ill-posed", (f"after step {k} ({cmds[k - 1]}) the states agree to "
                                 f"{agree:.1e}; REF from its dump with 17-digit coordinates ends "
                                 f"at E={r['energy']:.9g} {r['counts']}, with its 15-digit ones "
                                 f"at E={r15['energy']:.9g} {r15['counts']} (a 1e-15 change of "
                                 f"its input changes its result by {w_pert:.1e}): REF disagrees "
                                 f"with itself; pyevolver from the 17-digit dump: "
                                 f"E={p['energy']:.9g} {p['counts']}")
        return None, (f"after step {k}, the last where the states agree, pyevolver fed REF's "
                      f"state does not make REF's numbers and REF reproduces itself")
    return None, "no split point where pyevolver fed REF's state makes REF's numbers"


def _split_g(cmds):
    """``g N`` (N <= 10) as N commands ``g 1``: split points inside it."""
    out = []
    for c in cmds:
        m = re.fullmatch(r"\s*g\s+(\d+)\s*", c)
        out += ["g 1"] * int(m.group(1)) if m and 1 < int(m.group(1)) <= 10 else [c]
    return out


def _mirror_split(fe, seq, timeout, tree, tmp, r_full):
    """:func:`_mirror` with each ``g N`` split into ``g 1`` steps, against
    REF's uninterrupted run of the split sequence (the note says how far
    REF's own split run is from its unsplit one).  None when nothing is
    split or nothing is explained."""
    name, cmds, kind = seq
    split = _split_g(cmds)
    if split == list(cmds):
        return None
    sub = os.path.join(tmp, "split")
    os.makedirs(sub, exist_ok=True)
    script = os.path.join(sub, "s.cmd")
    _script(script, split)
    rout, _, rt = run(ref_cmd(script, fe), os.path.dirname(fe), timeout, merge=True)
    r2 = parse(rout, True)
    if rt or r2 is None or r2["energy"] is None:
        return None
    cls, why = _mirror(fe, (name, split, kind), timeout, tree, sub, r2)
    if not cls:
        return None
    return cls, (f"with each g N as g 1 steps (REF's own split run ends at "
                 f"E={r2['energy']:.9g} {r2['counts']}, its unsplit one at "
                 f"E={r_full['energy']:.9g} {r_full['counts']}): " + why)


CLASSES = ["match", "roundoff", "ill-posed", "small", "big", "py-refuses", "py-error", "py-trace", "py-timeout",
           "ref-error", "both-error"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--files", default="*", help="glob on the datafile's base name")
    ap.add_argument("--seqs", default="", help="comma-separated sequence names")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--all", action="store_true", help="every paper datafile too")
    ap.add_argument("--examples", action="store_true",
                    help="only the installed examples (issue 23's 25 x 17 cases)")
    ap.add_argument("--gogo", action="store_true",
                    help="only the datafiles' own gogo* commands (one case each)")
    ap.add_argument("--pyevolver", default=REPO,
                    help="the pyevolver tree to test (PYTHONPATH), this one by default")
    ap.add_argument("--quiet", action="store_true", help="only the non-matching rows")
    a = ap.parse_args()
    files = [f for f in datafiles(a.all) if fnmatch.fnmatch(os.path.basename(f), a.files)
             and (not a.examples or os.path.dirname(f) == EXAMPLES)]
    seqs = [s for s in SEQUENCES if not a.seqs or s[0] in a.seqs.split(",")]
    cases = [(f, s) for f in files for s in (gogo_sequences(f) if a.gogo else seqs)]
    results = []
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        futs = [ex.submit(one_case, f, s, a.timeout, a.pyevolver) for f, s in cases]
        for fut in futs:
            res = fut.result()
            results.append(res)
            if a.quiet and res["cls"] == "match":
                continue
            w = "" if res["worst"] is None else f"{res['worst']:.2e}"
            print(f"{os.path.basename(res['file']):42s} {res['seq']:14s} {res['cls']:11s} "
                  f"{w:9s} {res['note']}", flush=True)
    print()
    counts = {c: sum(r["cls"] == c for r in results) for c in CLASSES}
    print("  ".join(f"{c}={n}" for c, n in counts.items()), f"total={len(results)}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
