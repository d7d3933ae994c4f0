"""Closed triangle meshes for studies and tests: the regular m×n torus, the
refined icosahedron, and a minimal Evolver datafile writer.

All meshes are ``(X (nv, 3) float, F (nf, 3) int)`` with 0-based vertex
indices and triangles counter-clockwise seen from outside (positive volume).
"""
from __future__ import annotations

import numpy as np

from ..atomic import atomic_write


def _outward(X: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``F`` with every triangle reversed when the enclosed volume is negative."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    if np.einsum("ij,ij->i", a, np.cross(b, c)).sum() < 0:
        F = F[:, ::-1].copy()
    return F


def torus_grid(m: int, n: int, R: float = 2.0, r: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The regularly triangulated torus of the paper's Figure 1: ``m`` grid
    points around the minor circle, ``n`` around the major circle, every
    grid quad split along the same diagonal, so every vertex has valence 6.

    Vertex ``(i, j)`` (index ``i + m j``) is at minor angle φ = 2πi/m and major
    angle θ = 2πj/n: ``((R + r cos φ) cos θ, (R + r cos φ) sin θ, r sin φ)``.

    Returns ``X (m n, 3)``, ``F (2 m n, 3)``.
    """
    if m < 3 or n < 3:
        raise ValueError("torus_grid needs m, n >= 3")
    i, j = np.meshgrid(np.arange(m), np.arange(n), indexing="xy")   # index i + m j
    i, j = i.ravel(), j.ravel()
    phi = 2 * np.pi * i / m
    th = 2 * np.pi * j / n
    rho = R + r * np.cos(phi)
    X = np.stack([rho * np.cos(th), rho * np.sin(th), r * np.sin(phi)], 1)

    def v(a, b):
        return (a % m) + m * (b % n)
    F = np.concatenate([np.stack([v(i, j), v(i + 1, j), v(i + 1, j + 1)], 1),
                        np.stack([v(i, j), v(i + 1, j + 1), v(i, j + 1)], 1)])
    return X, _outward(X, F)


def torus_offset(m: int, n: int, R: float = 2.0,
                 r: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """The regular torus with offset rows: ``m`` points around the minor
    circle, ``n`` (even) rows around the major circle, odd rows turned by
    half a step (φ = 2π(i + ½)/m), each row joined to the next by a strip of
    triangles.  Every vertex has valence 6, as in :func:`torus_grid`.

    The two grids differ in their conformal structure when every triangle
    is taken equilateral (the structure of the paper's ``harmonic_energy``):
    with one diagonal direction the period lattice is spanned by ``m·(1, 0)``
    and ``n·(½, √3/2)``, a sheared lattice that no torus of revolution has;
    with offset rows it is ``m·(1, 0)`` and ``n·(0, √3/2)``, rectangular, the
    conformal class of a torus of revolution with ``√((R/r)² − 1) =
    n√3/(2m)`` (the Clifford torus, R/r = √2, is the square class).

    Vertex ``(i, j)`` has index ``i + m j``.  Returns ``X (m n, 3)``,
    ``F (2 m n, 3)``.
    """
    if m < 3 or n < 4 or n % 2:
        raise ValueError("torus_offset needs m >= 3 and an even n >= 4")
    i, j = np.meshgrid(np.arange(m), np.arange(n), indexing="xy")
    i, j = i.ravel(), j.ravel()
    phi = 2 * np.pi * (i + 0.5 * (j % 2)) / m
    th = 2 * np.pi * j / n
    rho = R + r * np.cos(phi)
    X = np.stack([rho * np.cos(th), rho * np.sin(th), r * np.sin(phi)], 1)

    def v(a, b):
        return (a % m) + m * (b % n)
    even = (j % 2 == 0)[:, None]
    # even row j: (i, j+1) lies half a step past (i, j); odd row: half a step before
    F1 = np.where(even, np.stack([v(i, j), v(i + 1, j), v(i, j + 1)], 1),
                  np.stack([v(i, j), v(i + 1, j), v(i + 1, j + 1)], 1))
    F2 = np.where(even, np.stack([v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)], 1),
                  np.stack([v(i, j), v(i + 1, j + 1), v(i, j + 1)], 1))
    return X, _outward(X, np.concatenate([F1, F2]))


def icosahedron() -> tuple[np.ndarray, np.ndarray]:
    """The unit icosahedron: ``X (12, 3)``, ``F (20, 3)``."""
    p = (1 + 5 ** 0.5) / 2
    X = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
                  [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]],
                 float)
    X /= np.linalg.norm(X, axis=1)[:, None]
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
                  [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
                  [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
                  [8, 6, 7], [9, 8, 1]])
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) < 0
    F[flip] = F[flip][:, ::-1]
    return X, F


def edges(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undirected edges ``E (ne, 2)`` (E[:, 0] < E[:, 1]) and ``idx (nf, 3)``:
    the edge of side k of each facet (from corner k to corner k + 1)."""
    tail, head = F, np.roll(F, -1, axis=1)
    lo, hi = np.minimum(tail, head).ravel(), np.maximum(tail, head).ravel()
    key = lo * (int(F.max()) + 1) + hi
    _, first, inv = np.unique(key, return_index=True, return_inverse=True)
    return np.stack([lo[first], hi[first]], 1), inv.reshape(F.shape)


def icosphere(level: int) -> tuple[np.ndarray, np.ndarray]:
    """The icosahedron refined ``level`` times (each triangle into four at
    its edge midpoints), vertices projected to the unit sphere:
    ``10 · 4^level + 2`` vertices (642, 2,562, 10,242 for levels 3, 4, 5)."""
    X, F = icosahedron()
    for _ in range(level):
        E, idx = edges(F)
        M = X[E[:, 0]] + X[E[:, 1]]
        M /= np.linalg.norm(M, axis=1)[:, None]
        e = idx + len(X)
        a, b, c = F[:, 0], F[:, 1], F[:, 2]
        F = np.stack([np.stack([a, e[:, 0], e[:, 2]], 1), np.stack([e[:, 0], b, e[:, 1]], 1),
                      np.stack([e[:, 2], e[:, 1], c], 1),
                      np.stack([e[:, 0], e[:, 1], e[:, 2]], 1)], 1).reshape(-1, 3)
        X = np.vstack([X, M])
    return X, F


def fe_text(X: np.ndarray, F: np.ndarray, header: str = "", face_attrs: str = "") -> str:
    """``(X, F)`` as the text of an Evolver datafile (vertices, edges, faces
    with signed edge ids); ``header`` (e.g. quantity declarations) goes on
    top, ``face_attrs`` (e.g. ``"tension 0"``) after every face."""
    E, idx = edges(F)
    sign = np.where(F == E[idx, 0], 1, -1)
    FE = sign * (idx + 1)
    out = [header.rstrip("\n") + "\n\n" if header else "", "vertices\n"]
    out += ["%d %.17g %.17g %.17g\n" % (k + 1, x, y, z) for k, (x, y, z) in enumerate(X.tolist())]
    out.append("\nedges\n")
    out += ["%d %d %d\n" % (k + 1, a, b) for k, (a, b) in enumerate((E + 1).tolist())]
    out.append("\nfaces\n")
    out += [("%d %d %d %d " % (k + 1, *row)) + face_attrs + "\n"
            for k, row in enumerate(FE.tolist())]
    return "".join(out)


def write_fe(path: str, X: np.ndarray, F: np.ndarray, header: str = "",
             face_attrs: str = "") -> str:
    """Write :func:`fe_text` of ``(X, F)`` to ``path``; returns ``path``."""
    with atomic_write(path, "w") as fh:
        fh.write(fe_text(X, F, header, face_attrs))
    return path
