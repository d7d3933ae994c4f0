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

Classes: ``match`` (max relative difference <= 1e-9), ``small`` (<= 1e-4),
``big``, ``py-refuses`` (pyevolver's "not supported in pyevolver: NAME"),
``py-error`` (pyevolver printed an error message the reference did not),
``py-trace`` (a Python traceback: always a bug), ``py-timeout``,
``ref-error`` (the reference printed ERROR or did not reach the tail; a
reference error ends its ``-f`` script), ``both-error``.
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


def run(cmd, cwd, timeout, env=None):
    try:
        p = subprocess.run(cmd, cwd=cwd, stdin=subprocess.DEVNULL, capture_output=True,
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


def one_case(fe, seq, timeout, tree=REPO):
    name, cmds, kind = seq
    with tempfile.TemporaryDirectory(prefix="dsweep") as tmp:
        script = os.path.join(tmp, "s.cmd")
        with open(script, "w") as f:
            f.write('printf "DS_BEGIN\\n"\n' + "\n".join(cmds + TAIL) + "\n")
        env = dict(os.environ, PYTHONPATH=tree)
        cwd = os.path.dirname(fe)
        pout, perr, ptime = run([sys.executable, "-m", "pyevolver", "-f", script, fe], cwd,
                                timeout, env)
        rout, rerr, rtime = run(["evolver-nox-d", "-p1", "-f", script, fe], cwd, timeout)
    p, r = parse(pout, False), parse(rout, True)
    # warnings (WARNING 1055 and its "Total difference" line) are not errors
    perr = "\n".join(l for l in perr.splitlines()
                     if l.strip() and not l.startswith(("WARNING", "Total difference")))
    res = {"file": os.path.relpath(fe, "/"), "seq": name, "worst": None, "note": ""}
    ref_bad = (rtime or r is None or r["error"] or "ERROR" in rerr or r["energy"] is None
               or r["energy"] != r["energy"])
    if "Traceback" in perr:
        res["cls"] = "py-trace"
        res["note"] = perr.strip().split("\n")[-1][:150]
    elif ptime:
        res["cls"] = "py-timeout"
    elif "not supported in pyevolver" in perr:
        res["cls"] = "both-error" if ref_bad else "py-refuses"
        m = re.search(r"not supported in pyevolver: [^\n]*", perr)
        res["note"] = m.group(0)[27:150]
    elif ref_bad:
        res["cls"] = "both-error" if (perr.strip() or p is None) else "ref-error"
        err = [l for l in rout.split("\n") if "ERROR" in l or "rror" in l]
        res["note"] = ("timeout " if rtime else "") + (err[0][:120] if err else "")
    elif perr.strip() or p is None or p["energy"] is None or p["energy"] != p["energy"]:
        res["cls"] = "py-error"
        res["note"] = perr.strip().replace("\n", " | ")[:150]
    else:
        worst, note = compare(p, r, kind)
        res["worst"], res["note"] = worst, note
        res["cls"] = "match" if worst <= 1e-9 else "small" if worst <= 1e-4 else "big"
        if res["cls"] != "match":
            res["py"] = {"g": p["g"][-3:], "E": p["energy"], "C": p["counts"]}
            res["ref"] = {"g": r["g"][-3:], "E": r["energy"], "C": r["counts"]}
    return res


CLASSES = ["match", "small", "big", "py-refuses", "py-error", "py-trace", "py-timeout",
           "ref-error", "both-error"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--files", default="*", help="glob on the datafile's base name")
    ap.add_argument("--seqs", default="", help="comma-separated sequence names")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--all", action="store_true", help="every paper datafile too")
    ap.add_argument("--gogo", action="store_true",
                    help="only the datafiles' own gogo* commands (one case each)")
    ap.add_argument("--pyevolver", default=REPO,
                    help="the pyevolver tree to test (PYTHONPATH), this one by default")
    ap.add_argument("--quiet", action="store_true", help="only the non-matching rows")
    a = ap.parse_args()
    files = [f for f in datafiles(a.all) if fnmatch.fnmatch(os.path.basename(f), a.files)]
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
