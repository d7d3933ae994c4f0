"""The built-in symmetry groups other than the torus (``SYMMETRY_GROUP
"rotate"`` and the rest): their elements as affine maps ``x -> A x + b``.

An edge's group element is an integer code (its ``wrap``); the head of the
edge seen from the tail is ``g(x_head) = A x_head + b``.  The encodings, the
products (``wrap_compose``) and the inverses (``wrap_inverse``) are REF's,
measured with ``evolver-nox-d`` (printing ``wrap_compose(a, b)`` and
``wrap_inverse(a)`` over tables of codes, and edge lengths from three
unit-vector tails to one head, which give ``g(x_head)``):

* ``rotate`` (``rotation_order`` n, default 4; ``generator_power`` p,
  default 1): code k turns the head by ``-2 pi p k / n`` about the z axis.
  Products and inverses are C remainders modulo n, the upper half less n
  (``[-n/2, n/2)`` for nonnegative codes; the command language passes
  its arguments as 32-bit unsigned numbers, so ``wrap_compose(1, -1)``
  is 1 for n = 3 while `r` composes 1 and -1 to 0);
* ``flip_rotate``: as ``rotate``, z flipped for odd k;
* ``xyz``: code k applies the cycle (x, y, z) -> (z, x, y) k times; the
  products and inverses of ``rotate`` with n = 3;
* ``cubocta`` (the manual's bits: 1, 2, 4 flip x, y, z; (code & 24) / 8
  cycles; 32 swaps x and y, in that order): REF's product keeps the sign
  part of ``b o a`` and the cycle part ``k_b + (-1)^{w_b} k_a`` (reduced
  once into 0..2, so 3 + 3 stays 3): not always the composition of the
  maps, and not associative; reproduced as measured;
* ``cubelat``: ``code & 63`` as ``cubocta``, then the translation
  ``code >> 6`` in the torus group's 6-bit fields; the product's
  translation is ``A_a t_b + t_a``;
* ``central_symmetry``: a nonzero code maps x to -x; the product is the
  bitwise exclusive or, every code its own inverse;
* ``screw_symmetry`` (``screw_height`` h, default 1; ``screw_angle`` in
  degrees, default 0): code k turns by ``k * angle`` and lifts by ``k h``;
  products add;
* ``quarter_turn`` (``quarter_turn_period`` P, required): the torus fields
  (i, j, k) map x to ``Z^k (x + (i, j, 0))`` with ``Z (x, y, z) = (-y, x,
  z + P)``; REF's product is the composition ``a o b`` except that the
  z power is ``k_a + (k_b mod 4)``.
"""
from __future__ import annotations

import math

import numpy as np

from .symmetry import decode_torus, encode_torus

#: the groups this module has (the torus group is model/symmetry.py's)
NAMES = ("rotate", "flip_rotate", "xyz", "cubocta", "cubelat", "central_symmetry",
         "screw_symmetry", "quarter_turn")

_U32 = 1 << 32
_C = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], float)     # (x, y, z) -> (z, x, y)
_W = np.array([[0, 1, 0], [1, 0, 0], [0, 0, 1]], float)     # swap x, y


def _sign(s):
    return np.diag([-1.0 if s & 1 else 1.0, -1.0 if s & 2 else 1.0, -1.0 if s & 4 else 1.0])


def _cub_matrix(c: int) -> np.ndarray:
    k, w = (c >> 3) & 3, (c >> 5) & 1
    return np.linalg.matrix_power(_W, w) @ np.linalg.matrix_power(_C, k) @ _sign(c & 7)


def _conj_bits(s: int, k: int, w: int) -> int:
    """Sign bits of ``M^-1 S_s M``, ``M = W^w C^k``."""
    M = np.linalg.matrix_power(_W, w) @ np.linalg.matrix_power(_C, k % 3)
    d = np.diag(M.T @ _sign(s) @ M)
    return int(d[0] < 0) | int(d[1] < 0) << 1 | int(d[2] < 0) << 2


def _cub_tables():
    mats = np.stack([_cub_matrix(c) for c in range(64)])
    comp = np.zeros((64, 64), np.int64)
    for a in range(64):
        s1, k1, w1 = a & 7, (a >> 3) & 3, (a >> 5) & 1
        for b in range(64):
            s2, k2, w2 = b & 7, (b >> 3) & 3, (b >> 5) & 1
            k = k2 - k1 if w2 else k2 + k1
            if k < 0:
                k += 3
            if k >= 3:
                k -= 3
            comp[a, b] = (s1 ^ _conj_bits(s2, k1, w1)) | k << 3 | (w1 ^ w2) << 5
    inv = np.zeros(64, np.int64)
    for a in range(64):
        k, w = (a >> 3) & 3, (a >> 5) & 1
        ki = k if w else (-k + 3 if k > 0 else 0)
        M = mats[a].T                                   # the inverse map
        R = np.linalg.matrix_power(_W, w) @ np.linalg.matrix_power(_C, ki % 3)
        d = np.diag(R.T @ M)
        inv[a] = (int(d[0] < 0) | int(d[1] < 0) << 1 | int(d[2] < 0) << 2) | ki << 3 | w << 5
    return mats, comp, inv


_CUB = None


def _cub():
    global _CUB
    if _CUB is None:
        _CUB = _cub_tables()
    return _CUB


def _rot_z(theta: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    A = np.zeros((len(theta), 3, 3))
    A[:, 0, 0] = c
    A[:, 0, 1] = -s
    A[:, 1, 0] = s
    A[:, 1, 1] = c
    A[:, 2, 2] = 1.0
    return A


def _quarter(k: np.ndarray) -> np.ndarray:
    return _rot_z(np.mod(k, 4) * (math.pi / 2)).round()


class Group:
    """A symmetry group's elements: ``affine``, ``compose``, ``inverse``
    on integer code arrays (vectorized)."""

    def __init__(self, name: str, params: dict):
        self.name = name
        self.n = int(round(float(params.get("rotation_order", 4)))) if name != "xyz" else 3
        self.power = float(params.get("generator_power", 1))
        self.height = float(params.get("screw_height", 1.0))
        self.angle = float(params.get("screw_angle", 0.0))
        self.period = params.get("quarter_turn_period")

    # -- the maps ------------------------------------------------------------
    def affine(self, codes) -> tuple[np.ndarray, np.ndarray]:
        """(A (n, 3, 3), b (n, 3)) of the codes ``(n,)``."""
        c = np.asarray(codes, np.int64).ravel()
        m = len(c)
        b = np.zeros((m, 3))
        nm = self.name
        if nm in ("rotate", "flip_rotate"):
            A = _rot_z(-2 * math.pi * self.power * c / self.n)
            if nm == "flip_rotate":
                A[:, 2, 2] = np.where(c % 2 == 1, -1.0, 1.0)
        elif nm == "xyz":
            Cs = np.stack([np.eye(3), _C, _C @ _C])
            A = Cs[np.mod(c, 3)]
        elif nm in ("cubocta", "cubelat"):
            A = _cub()[0][c & 63]
            if nm == "cubelat":
                b = decode_torus(c >> 6)
        elif nm == "central_symmetry":
            A = np.where((c != 0)[:, None, None], -np.eye(3), np.eye(3))
        elif nm == "screw_symmetry":
            A = _rot_z(c * math.radians(self.angle))
            b[:, 2] = c * self.height
        else:                                   # quarter_turn
            f = decode_torus(c)
            A = _quarter(f[:, 2])
            t = f.copy()
            t[:, 2] = 0.0
            b = np.einsum("nij,nj->ni", A, t)
            b[:, 2] += f[:, 2] * float(self.period)
        return A, b

    def function(self, name: str, *args):
        """The command language's ``name(*args)`` (:func:`function_value`)."""
        return function_value(self, name, *args)

    # -- products and inverses (REF's) ----------------------------------------
    def _mod(self, x):
        # C's remainder (the dividend's sign), then the upper half less n:
        # in [-n/2, n/2) for the command language's unsigned arguments
        n = self.n
        u = np.fmod(x, n)
        return np.where(2 * u >= n, u - n, u)

    def compose(self, a, b) -> np.ndarray:
        """REF's ``wrap_compose(a, b)`` (arrays of any one shape)."""
        a, b = np.broadcast_arrays(np.asarray(a, np.int64), np.asarray(b, np.int64))
        if a.ndim != 1:
            return self.compose(a.ravel(), b.ravel()).reshape(a.shape)
        nm = self.name
        if nm in ("rotate", "flip_rotate", "xyz"):
            n = self.n
            return self._mod(np.fmod(a, n) + np.fmod(b, n))
        if nm == "central_symmetry":
            return a ^ b
        if nm == "screw_symmetry":
            return a + b
        if nm == "cubocta":
            return _cub()[1][a & 63, b & 63]
        if nm == "cubelat":
            rot = _cub()[1][a & 63, b & 63]
            A = _cub()[0][a & 63]
            t = np.einsum("...ij,...j->...i", A, decode_torus(np.atleast_1d(b >> 6))) \
                + decode_torus(np.atleast_1d(a >> 6))
            return (rot | encode_torus(t) << 6).reshape(np.shape(rot))
        # quarter_turn: the maps' composition a o b, z power k_a + (k_b mod 4)
        fa, fb = decode_torus(np.atleast_1d(a)), decode_torus(np.atleast_1d(b))
        fa, fb = np.broadcast_arrays(fa, fb)
        Aa = _quarter(fa[:, 2])
        tb = fb.copy()
        tb[:, 2] = 0.0
        ij = fa.copy()
        ij[:, 2] = 0.0
        # a(b(x)) = Z^ka(Z^kb(x + tb) + ta) = Z^(ka+kb)(x + tb + Z^-kb ta)
        Zb_inv = _quarter(-fb[:, 2])
        tt = tb + np.einsum("nij,nj->ni", Zb_inv, ij)
        tt[:, 2] = fa[:, 2] + np.mod(fb[:, 2], 4)
        del Aa
        return encode_torus(tt).reshape(np.broadcast(a, b).shape)

    def inverse(self, a) -> np.ndarray:
        """REF's ``wrap_inverse(a)`` (an array of any shape)."""
        a = np.asarray(a, np.int64)
        if a.ndim != 1:
            return self.inverse(a.ravel()).reshape(a.shape)
        nm = self.name
        if nm in ("rotate", "flip_rotate", "xyz"):
            n = self.n
            return self._mod(n - np.fmod(a, n))
        if nm == "central_symmetry":
            return a
        if nm == "screw_symmetry":
            return -a
        if nm == "cubocta":
            return _cub()[2][a & 63]
        if nm == "cubelat":
            A = _cub()[0][a & 63]
            t = -np.einsum("...ji,...j->...i", A, decode_torus(np.atleast_1d(a >> 6)))
            return (_cub()[2][a & 63] | encode_torus(t) << 6).reshape(np.shape(a))
        f = decode_torus(np.atleast_1d(a))           # quarter_turn: the true inverse
        # x = Z^-k(y) - t: code (i', j', -k) with (i', j') = -Z^k t
        t = f.copy()
        t[:, 2] = 0.0
        ij = -np.einsum("nij,nj->ni", _quarter(f[:, 2]), t)
        ij[:, 2] = -f[:, 2]
        return encode_torus(ij).reshape(np.shape(a))


def function_value(group: "Group", name: str, *args):
    """The command language's ``wrap_compose(a, b)`` / ``wrap_inverse(a)``:
    REF passes the arguments as unsigned 32-bit numbers (``-1`` is
    4294967295), which matters where the group does not reduce them
    (screw_symmetry, central_symmetry, cubelat)."""
    u = [np.mod(np.rint(np.asarray(a, float)).astype(np.int64), _U32) for a in args]
    out = group.compose(*u) if name == "wrap_compose" else group.inverse(*u)
    return np.asarray(out, float)


def group_of(surface) -> Group | None:
    """The surface's group object (None without one and for the torus group,
    which is the torus model's)."""
    name = getattr(surface, "symmetry_group", None)
    if name is None or name not in NAMES:
        return None
    return Group(name, surface.params)
