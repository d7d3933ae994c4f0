"""``refine edges`` in the torus model with a parametric boundary whose
edge crosses the periodic wrap (the shengdie torus sheets' free ends): the
new vertex goes to the wrapped edge's midpoint, not the chord's (half a
period off before).  A 4×4 periodic sheet whose x = 0 column is on the
boundary ``x = 0, y = p1, z = p2``; compared with the Evolver run live."""
import math

from comparison import _same, run_pyevolver
from reference import run_reference

N = 4


def _sheet():
    out = ["TORUS", "periods", "1 0 0", "0 1 0", "0 0 1", "",
           "quantity bend energy method star_perp_sq_mean_curvature global", "",
           "boundary 1 parameters 2", "x1: 0", "x2: p1", "x3: p2", "", "vertices"]
    vid = lambda i, j: (j % N) * N + (i % N) + 1       # noqa: E731
    for j in range(N):
        for i in range(N):
            x, y = i / N, j / N
            z = 0.08 * math.sin(2 * math.pi * x) * math.cos(2 * math.pi * y)
            if i == 0:
                out.append(f"{vid(i, j)} {y:.12f} {z:.12f} boundary 1")
            else:
                out.append(f"{vid(i, j)} {x:.12f} {y:.12f} {z:.12f}")
    out += ["", "edges"]
    eid = {}
    for j in range(N):
        for i in range(N):
            for typ, (di, dj) in (("h", (1, 0)), ("u", (0, 1)), ("d", (1, 1))):
                eid[typ, i, j] = k = len(eid) + 1
                wx, wy = ("+" if i + di >= N else "*"), ("+" if j + dj >= N else "*")
                on = " boundary 1" if typ == "u" and i == 0 else ""
                out.append(f"{k} {vid(i, j)} {vid(i + di, j + dj)} {wx} {wy} *{on}")
    out += ["", "faces"]
    for j in range(N):
        for i in range(N):
            f = 2 * (j * N + i)
            out.append(f"{f + 1} {eid['h', i, j]} {eid['u', (i + 1) % N, j]} -{eid['d', i, j]}")
            out.append(f"{f + 2} {eid['d', i, j]} -{eid['h', i, (j + 1) % N]} -{eid['u', i, j]}")
    return "\n".join(out) + "\n"


def test_boundary_midpoint_across_the_wrap(evolver, tmp_path):
    fe = tmp_path / "tb.fe"
    fe.write_text(_sheet())
    script = ("refine edges\n"
              'printf "%.12g %.12g %.12g\\n", total_area, sum(vertex where on_boundary 1, y), '
              "sum(vertex where on_boundary 1, p1)\n"
              'U\ng 3\nprintf "%.12g %.12g\\n", total_energy, total_area\n')
    ref = [ln for ln in run_reference(evolver, str(fe), script, cwd=str(tmp_path))
           if ln[:1].isdigit()]
    _, out, err = run_pyevolver(str(fe), script + "q\n", cwd=str(tmp_path))
    out = [ln for ln in out if ln[:1].isdigit()]
    assert ref[0].split()[1] == "3.5", ref           # 0.875 for the wrapped edge's midpoint
    assert _same(out, ref, rtol=1e-10), (out, ref, err)
