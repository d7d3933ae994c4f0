"""Mutation fuzzing helpers shared by tests/test_fuzz.py.

Inputs are the shipped examples mutated the way a careless edit or a broken
transfer would: tokens deleted, duplicated, swapped or replaced, the text
truncated, random bytes inserted, numbers made huge, expressions nested
deeply.  A mutator is a pure function of a ``random.Random``, so a failing
input is reproduced from its seed.

Every run happens under :func:`time_limit`: an input that takes longer is a
hang (raised as :class:`Hang`, a ``BaseException`` that no ``except
Exception`` in the code under test can swallow).
"""
from __future__ import annotations

import contextlib
import glob
import os
import re
import signal

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
EXAMPLES = "/usr/share/doc/evolver/examples"

_TOKEN = re.compile(r"\s+|[A-Za-z_][A-Za-z0-9_]*|\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|\.\d+|\S")
_NUMBER = re.compile(r"\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|\.\d+")

HUGE = ["1e308", "1e309", "-1e400", "99999999999999999999999999", "1000000000000",
        "4294967297", "9223372036854775808", "1e-320", "0", "-0", "0x7fffffffffffffff",
        "1" * 400, "2147483648", "1e6", "1000000", "-1", "nan", "inf"]

# words that matter to the datafile and command grammars
VOCAB = """vertices edges faces facets bodies read constraint boundary parameter
quantity method_instance method energy content fixed info_only conserved formula
function global convex modulus tension density volume pressure constraints
boundary torus periods space_dimension scale define attribute integer real
e1 e2 e3 c1 c2 c3 x1 x2 x3 p1 p2 q1 q2 q3 scalar_integrand vector_integrand
facet_scalar_integral edge_vector_integral vertex_scalar_integral
star_perp_sq_mean_curvature sq_mean_curvature gravity_constant original color
#define #include if then else while do for foreach where procedure local return
break continue print printf list set unset fix unfix refine delete edgeswap read
dump load replace_load addload g r u V t w l K n j m hessian hessian_seek bfgs
quit q exit abort histogram sum max min avg count sprintf sizeof is_defined vertex
edge facet body x y z id oid length area valence on_constraint total_energy
total_area vertex_count := += -= *= /= ++ -- >> >>> | { } ( ) [ ] ; , . :
" // /* */ \\ ? ! && || == != <= >= < > ^ ** % mod idiv exec eval system shell
""".split()

RANDOM_BYTES = ["\x00", "\xff", "\x1a", "\x0b", "\x0c", "\r", "\t", "\x7f", "é", "\u2028",
                "\x85", "\ufeff", "\\", '"', "'", "`", "$", "@", "#", "~", "\n\n\n"]


class Hang(BaseException):
    """An input ran longer than its time limit."""


@contextlib.contextmanager
def time_limit(seconds):
    """Raise :class:`Hang` in the running code after ``seconds`` (real time)."""
    def handler(signum, frame):
        raise Hang(f"no result after {seconds} s")
    old = signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def tokens(text):
    return _TOKEN.findall(text)


def _words(toks):
    return [k for k, t in enumerate(toks) if not t.isspace()]


def _deep(rng):
    depth = rng.choice([10, 100, 300, 1000, 3000])
    kind = rng.randrange(5)
    if kind == 0:
        return "(" * depth + "1" + ")" * depth
    if kind == 1:
        return "-" * depth + "1"
    if kind == 2:
        return "{" * depth + "print 1" + "}" * depth
    if kind == 3:
        return "1" + "+1" * depth
    return "sin(" * depth + "1" + ")" * depth


def mutate(text, rng, others=()):
    """One to three random mutations of ``text`` (a string)."""
    toks = tokens(text)
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        words = _words(toks)
        op = rng.randrange(12)
        if not words and op < 9:
            op = 9
        if op == 0:                                   # delete a token
            del toks[rng.choice(words)]
        elif op == 1:                                 # duplicate a token
            k = rng.choice(words)
            toks.insert(k, toks[k] + " ")
        elif op == 2:                                 # swap two tokens
            a, b = rng.choice(words), rng.choice(words)
            toks[a], toks[b] = toks[b], toks[a]
        elif op == 3:                                 # replace by another token
            toks[rng.choice(words)] = toks[rng.choice(words)]
        elif op == 4:                                 # a huge or odd number
            nums = [k for k in words if _NUMBER.fullmatch(toks[k])]
            k = rng.choice(nums or words)
            toks[k] = rng.choice(HUGE)
        elif op == 5:                                 # a grammar word
            toks.insert(rng.choice(words), " " + rng.choice(VOCAB) + " ")
        elif op == 6:                                 # delete a line
            lines = "".join(toks).split("\n")
            del lines[rng.randrange(len(lines))]
            toks = tokens("\n".join(lines))
        elif op == 7:                                 # duplicate a line
            lines = "".join(toks).split("\n")
            k = rng.randrange(len(lines))
            lines.insert(k, lines[k])
            toks = tokens("\n".join(lines))
        elif op == 8:                                 # deep nesting
            nums = [k for k in words if _NUMBER.fullmatch(toks[k])]
            toks[rng.choice(nums or words)] = _deep(rng)
        elif op == 9:                                 # random bytes
            k = rng.randrange(len(toks) + 1)
            toks.insert(k, "".join(rng.choice(RANDOM_BYTES) if rng.random() < 0.7
                                   else chr(rng.randrange(256)) for _ in range(rng.randrange(1, 4))))
        elif op == 10:                                # truncate
            s = "".join(toks)
            toks = tokens(s[:rng.randrange(len(s) + 1)])
        else:                                         # splice in another file's lines
            if others:
                src = rng.choice(others).split("\n")
                k = rng.randrange(len(src))
                lines = "".join(toks).split("\n")
                lines.insert(rng.randrange(len(lines) + 1),
                             "\n".join(src[k:k + rng.randrange(1, 4)]))
                toks = tokens("\n".join(lines))
    return "".join(toks)


def read_text(path):
    with open(path, "rb") as fh:
        return fh.read().decode("latin-1")


def seed_datafiles(small_only=True):
    """The shipped datafiles (examples, datafiles/, tests/data): (name, text).
    ``small_only`` keeps those under 3 kB (fast to read: the CI corpus)."""
    paths = sorted(glob.glob(os.path.join(EXAMPLES, "*.fe")))
    paths += sorted(glob.glob(os.path.join(ROOT, "datafiles", "**", "*.fe"), recursive=True))
    paths += sorted(glob.glob(os.path.join(HERE, "data", "*.fe")))
    out = []
    for p in paths:
        t = read_text(p)
        if small_only and len(t) > 3000:
            continue
        out.append((p, t))
    return out


def seed_scripts():
    """Command texts: the shipped .cmd scripts, the tests' scripts and the
    read sections of the datafiles."""
    paths = sorted(glob.glob(os.path.join(EXAMPLES, "*.cmd")))
    paths += sorted(glob.glob(os.path.join(HERE, "data", "*.cmd")))
    out = [(p, read_text(p)) for p in paths]
    for p, t in seed_datafiles(small_only=False):
        m = re.search(r"^\s*read\b", t, re.I | re.M)
        if m:
            out.append((p + ":read", t[m.end():]))
    return out
