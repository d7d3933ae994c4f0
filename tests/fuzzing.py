"""Mutation fuzzing helpers shared by tests/robustness/test_fuzz.py.

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
import io
import os
import re
import signal

import numpy as np

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
    """Raise :class:`Hang` in the running code after ``seconds`` of CPU time
    (a busy machine does not make a slow input a hang), or after six times
    as long in real time (an input blocked on I/O)."""
    def handler(signum, frame):
        raise Hang(f"no result after {seconds} s of CPU time"
                   if signum == signal.SIGPROF else f"no result after {6 * seconds} s")
    old = signal.signal(signal.SIGPROF, handler), signal.signal(signal.SIGALRM, handler)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    signal.setitimer(signal.ITIMER_REAL, 6 * seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGPROF, old[0])
        signal.signal(signal.SIGALRM, old[1])


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


def _methods():
    try:
        from pyevolver.methods import METHODS
        return sorted(METHODS) or ["facet_area"]
    except ImportError:                 # pragma: no cover
        return ["facet_area"]


_VALUES = ["1", "0", "-1", "0.5", "1e300", "-1e300", "2^1000", "1/0", "0/0", "pi", "x", "z",
           "p1", "1e-300", "99", "-0"]


_SETTINGS = ["scale", "scale_limit", "gravity_constant", "constraint_tolerance",
             "space_dimension", "integral_order", "target_tolerance"]
_FLAGS = ["symmetric_content", "torus", "torus_filled", "periods 1 0 0 0 1 0 0 0 1", "string",
          "soapfilm", "linear", "keep_originals"]

# templates of top-section declarations: f(rng, v) with v() a random value
_DECLARATIONS = [
    lambda rng, v: (f"quantity q{rng.randrange(3)} "
                    f"{rng.choice(['energy', 'fixed = ' + v(), 'info_only', 'conserved'])} "
                    f"method {rng.choice(_methods())} {rng.choice(['global', ''])}"),
    lambda rng, v: (f"constraint {rng.randrange(1, 4)} "
                    f"{rng.choice(['', 'nonnegative', 'convex', 'global'])} formula: "
                    f"{rng.choice(['x', 'z', 'x^2+y^2', 'atan(z)', '0*x'])} = {v()}"),
    lambda rng, v: (f"boundary {rng.randrange(1, 3)} parameters {rng.randrange(0, 4)} "
                    f"x1: {v()} x2: {rng.choice(['p1', 'cos(p1)', v()])} x3: {v()}"),
    lambda rng, v: (f"define {rng.choice(['vertex', 'edge', 'facet', 'body'])} attribute "
                    f"aa{rng.randrange(2)} {rng.choice(['real', 'integer'])}"
                    f"{rng.choice(['', '[2]', '[0]'])}"),
    lambda rng, v: f"parameter {rng.choice(['pp', 'rad', 'x', 'pi'])} = {v()}",
    lambda rng, v: f"{rng.choice(_SETTINGS)} {v()}",
    lambda rng, v: (f"method_instance mi{rng.randrange(2)} method {rng.choice(_methods())} "
                    f"{rng.choice(['global', ''])}"),
    lambda rng, v: rng.choice(_FLAGS),
    lambda rng, v: f"quantity qf energy function mi0.value * {v()}",
]


def _declaration(rng):
    """A random top-section declaration (quantities with every registered
    method, constraints, boundaries, attributes, settings)."""
    return rng.choice(_DECLARATIONS)(rng, lambda: rng.choice(_VALUES))


def _attribute(rng):
    """Random attributes for an element line."""
    v = lambda: rng.choice(_VALUES[:10])                    # noqa: E731
    return rng.choice([f"constraint {rng.randrange(0, 4)}", f"boundary {rng.randrange(0, 3)}",
                       "fixed", f"tension {v()}", f"density {v()}", f"volume {v()}",
                       f"pressure {v()}", f"color {v()}", "no_refine", f"q{rng.randrange(3)}",
                       f"mi{rng.randrange(2)}", f"aa{rng.randrange(2)} {v()}", f"q0-",
                       f"original {v()}", "* + -", "bare", f"volconst {v()}"])


def _structured(text, rng):
    """A declaration at the top, attributes on an element line, or a
    section header moved."""
    lines = text.split("\n")
    k = rng.randrange(3)
    if k == 0:
        lines.insert(rng.randrange(min(len(lines), 8) + 1), _declaration(rng))
    elif k == 1:
        numeric = [i for i, l in enumerate(lines) if l[:1].isdigit()]
        if numeric:
            i = rng.choice(numeric)
            lines[i] = lines[i] + " " + _attribute(rng)
    else:
        heads = [i for i, l in enumerate(lines)
                 if l.strip().lower().split()[:1] in (["vertices"], ["edges"], ["faces"], ["bodies"])]
        if heads:
            i = rng.choice(heads)
            head = lines.pop(i)
            lines.insert(rng.randrange(len(lines) + 1), head)
    return "\n".join(lines)


def mutate(text, rng, others=()):
    """One to three random mutations of ``text`` (a string)."""
    if rng.random() < 0.25:
        text = _structured(text, rng)
    toks = tokens(text)
    for _ in range(rng.choice((0, 1, 1, 1, 2, 3))):
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


# ---------------------------------------------------------------------------
# random commands: small, fast, and reaching every kind of statement

_NUMS = ["0", "1", "2", "3", "-1", "0.5", "1e10", "-1e300", "1e308*10", "0/0", "1/0", "7.25",
         "2^1000", "-0", "1e-300", "4294967296", "vertex_count", "edge_count+1", "facet_count",
         "pi", "random", "total_energy"]
_KINDS = ["vertex", "edge", "facet", "body", "facetedge"]
_ATTRS = ["x", "y", "z", "id", "oid", "length", "area", "volume", "target", "pressure",
          "tension", "fixed", "valence", "color", "original", "no_refine", "density",
          "volconst", "on_constraint 1", "vertex_normal[1]", "x[2]", "edge[1]", "vertex[2]",
          "facet[1]", "zz", "__class__"]
_FORMATS = ['"%d\\n"', '"%g %s\\n"', '"%*d\\n"', '"%.*f\\n"', '"%c%c\\n"', '"%%%5.2e\\n"',
            '"%x %o\\n"', '"%s\\n"', '"%n\\n"', '"%99999999d"', '"{0.__class__}\\n"', '"%-+ #020.10g"']
_WORDS = ["g", "r", "u", "V", "t", "w", "l", "K", "n", "j", "m", "U", "G", "v",
          "recalc", "hessian", "hessian_seek", "bfgs", "newton", "raw", "rawest", "optimise",
          "history", "optimize", "conj_grad", "quiet", "rawv",
          "rawestv", "equiangulate", "check_increase", "autochop", "gravity", "ribiere",
          "show_vol", "linear", "normal_curvature", "effective_area", "autopop", "edgeweed",
          "areaweed", "notch", "edge_divide", "zoom", "o", "O", "s", "P", "saddle", "system",
          "shell", "exec", "eval", "__import__", "os", "load_library"]


def _num(rng):
    return rng.choice(_NUMS)


def _expr(rng, depth=0):
    k = rng.randrange(9 if depth < 2 else 3)
    if k == 0:
        return _num(rng)
    if k == 1:
        return rng.choice(["aa", "bb", "arr[1]", "arr[0]", "arr[99]", "ss", "zz", "xx",
                           "total_area", "body_count", "scale", "'q'", '"str"'])
    if k == 2:
        return f"{rng.choice(_KINDS[:4])}[{_num(rng)}].{rng.choice(_ATTRS)}"
    if k == 3:
        op = rng.choice(["+", "-", "*", "/", "^", "%", " mod ", " idiv ", "==", "<", "&&",
                         "||", " imod ", "**"])
        return f"({_expr(rng, depth + 1)}{op}{_expr(rng, depth + 1)})"
    if k == 4:
        f = rng.choice(["sin", "sqrt", "log", "exp", "atan2", "acos", "floor", "abs",
                        "maximum", "sizeof", "is_defined", "sum", "max", "count", "avg"])
        if f in ("sum", "max", "count", "avg"):
            return f"{f}({rng.choice(_KINDS[:4])}, {_expr(rng, depth + 1)})"
        if f in ("atan2", "maximum"):
            return f"{f}({_expr(rng, depth + 1)}, {_expr(rng, depth + 1)})"
        if f == "is_defined":
            return f'is_defined("{rng.choice(["aa", "zz", "vertex", ""])}")'
        return f"{f}({_expr(rng, depth + 1)})"
    if k == 5:
        return f"({_expr(rng, depth + 1)} ? {_expr(rng, depth + 1)} : {_expr(rng, depth + 1)})"
    if k == 6:
        return f'sprintf({rng.choice(_FORMATS)}, {_expr(rng, depth + 1)})'
    if k == 7:
        return f"-{_expr(rng, depth + 1)}"
    return f"ff({_expr(rng, depth + 1)})"


def _gen(rng):
    kind = rng.choice(_KINDS)
    g = rng.choice([kind, f"{kind}[{_num(rng)}]", f"{kind} vv", f"vertex[1].{kind}",
                    f"{kind}[1].vertex", f"{kind}[2].edge[{_num(rng)}]"])
    if rng.random() < 0.5:
        g += f" where {_expr(rng, 2)}"
    return g


def _q(text):
    return '"' + text + '"'


# templates of simple commands: f(rng, e) with e a random expression
_SIMPLE = [
    lambda rng, e: f"{rng.choice(['aa', 'bb', 'ss', 'xx', 'arr[1]', 'arr[5][2]'])} := {e}",
    lambda rng, e: f"{rng.choice(['aa', 'bb'])} {rng.choice(['+=', '-=', '*=', '/=', '++', '--'])} {e}",
    lambda rng, e: f"print {e}",
    lambda rng, e: f"printf {rng.choice(_FORMATS)}, {e}, {_expr(rng)}",
    lambda rng, e: f"{rng.choice(_WORDS)} {rng.choice(['', _num(rng), e])}",
    lambda rng, e: f"list {_gen(rng)}",
    lambda rng, e: f"set {rng.choice(_KINDS[:4])} {rng.choice(_ATTRS[:18])} {e}",
    lambda rng, e: f"{rng.choice(['fix', 'unfix'])} {_gen(rng)}",
    lambda rng, e: f"{rng.choice(['refine', 'delete', 'edgeswap'])} {_gen(rng)}",
    lambda rng, e: f"define arr {rng.choice(['real', 'integer', 'string'])}[{_num(rng)}]",
    lambda rng, e: (f"define {rng.choice(_KINDS)} attribute zz {rng.choice(['real', 'integer'])}"
                    f"{rng.choice(['', '[2]', '[' + _num(rng) + ']'])}"),
    lambda rng, e: f"{rng.choice(_KINDS[:4])}[{_num(rng)}].{rng.choice(_ATTRS)} := {e}",
    lambda rng, e: f"histogram({_gen(rng)}, {e})",
    lambda rng, e: (f"unset {rng.choice(_KINDS[:4])} "
                    f"{rng.choice(['fixed', 'target', 'constraint 1', 'zz'])}"),
    lambda rng, e: (f'{rng.choice(["dump", "read", "load", "addload", "replace_load"])} '
                    f'{rng.choice(["", _q("out.fe"), _q("/dev/zero"), _q(""), e])}'),
    lambda rng, e: (f"{{ {random_command(rng, 2)} }} {rng.choice(['>>', '>>>', '|'])} "
                    f'{rng.choice([_q("o.txt"), _q("/dev/null"), e])}'),
    lambda rng, e: (f"{rng.choice(['quiet', 'conj_grad', 'autorecalc', 'gravity'])} "
                    f"{rng.choice(['on', 'off', e])}"),
    lambda rng, e: "abort" if rng.random() < 0.2 else f"return {e}",
    lambda rng, e: f"break {rng.choice(['', '2', e])}",
    lambda rng, e: f"local aa; aa := {e}",
    lambda rng, e: (f"body[{_num(rng)}].{rng.choice(['target', 'pressure', 'volconst', 'density'])}"
                    f" := {e}"),
    lambda rng, e: (f"{rng.choice(['g', 'r', 'u', 'V', 'hessian', 'newton'])} "
                    f"{rng.choice(['', '2', _num(rng)])}"),
    lambda rng, e: _quantity_command(rng, e),
]

# templates of compound commands: f(rng, e, inner, other) with two random
# inner commands
_COMPOUND = [
    lambda rng, e, a, b: f"if {e} then {a} else {b}",
    lambda rng, e, a, b: f"for (aa := 0; aa < {rng.choice(['3', e])}; aa++) {{ {a} }}",
    lambda rng, e, a, b: f"foreach {_gen(rng)} do {{ {a} }}",
    lambda rng, e, a, b: f"while {e} do {{ {a}; break }}",
    lambda rng, e, a, b: f"do {{ {a} }} while {e}",
    lambda rng, e, a, b: f"gogo := {{ {a} }}; gogo {rng.choice(['', '2', e])}",
    lambda rng, e, a, b: (f"function real ff(real xx) {{ {a}; return xx*2 }}; "
                          f"procedure pp(real yy) {{ {b} }}; pp({e})"),
    lambda rng, e, a, b: f"{rng.choice(['cc', 'r', 'g'])} :::= {{ {a} }}; {rng.choice(['cc', 'r', 'g'])}",
]


def _quantity_command(rng, e):
    q = rng.choice(_QNAMES)
    return rng.choice([
        f"{q}.{rng.choice(['target', 'modulus', 'tolerance', 'value', 'pressure'])} := {e}",
        f"print {q}.{rng.choice(['value', 'target', 'pressure'])}",
        f"{rng.choice(['fix', 'unfix'])} {q}", f"set {q} target {e}", f"hessian_seek {e}",
        f"set body target {e}", "unset body target", f"delete edge where length < {e}",
        f"refine edge where length > {e}", f"set edge tension {e}",
        f"bfgs {rng.choice(['1', '3', e])}"])


def random_command(rng, depth=0):
    """One random command of the Evolver language (most of them fail:
    wrong types, missing elements, huge counts; all must fail cleanly)."""
    e = _expr(rng)
    if depth < 2 and rng.random() < 0.25:
        make = rng.choice(_COMPOUND)
        return make(rng, e, random_command(rng, depth + 1), random_command(rng, depth + 1))
    return rng.choice(_SIMPLE)(rng, e)


_QNAMES = ["q0", "mi0", "sqcurve", "bend", "surf", "tmc", "sqm", "willmore", "larea", "lvol",
           "surface_area", "volume", "total_area"]


#: run once in each interpreter session: the names random commands use
PRELUDE = ('aa := 1; bb := 2; xx := 0.5; zz := 3; ss := "s"; define arr real[5][2]; '
           'function real ff(real yy) { return yy/2 }')


def random_script(rng):
    return "\n".join(random_command(rng) for _ in range(rng.randrange(1, 3)))


def script_window(rng, scripts):
    """A few lines of a shipped script, mutated."""
    name, text = rng.choice(scripts)
    lines = text.split("\n")
    k = rng.randrange(len(lines))
    window = "\n".join(lines[k:k + rng.randrange(1, 6)])
    return name, mutate(window, rng, [t for _, t in scripts[:8]])


# ---------------------------------------------------------------------------
# the checks: a located error or a valid surface, never a traceback or a hang

#: seconds after which one input counts as a hang
HANG_SECONDS = 10.0

#: inputs run by each fuzz target in this test session (reported at the end)
COUNTS = {}

#: (wall, CPU) seconds each fuzz target ran (hypothesis included)
TIMES = {}


def count(target, n=1):
    COUNTS[target] = COUNTS.get(target, 0) + n


class FuzzFailure(AssertionError):
    """An input produced a traceback, an unlocated error or a hang."""


def _fail(kind, what, text, exc=None):
    import traceback
    tb = "" if exc is None else "".join(traceback.format_exception(type(exc), exc,
                                                                  exc.__traceback__))
    raise FuzzFailure(f"{kind} on {what}:\n--- input ---\n{text[:3000]}\n--- end ---\n{tb}")


def check_surface(s):
    """The invariants of a valid surface: array shapes, indices in range,
    finite coordinates, a computable energy."""
    from pyevolver.geometry.kernels import edge_index
    nv, ne, nf = s.nv, s.ne, s.nf
    assert s.X.ndim == 2 and s.X.shape[0] == nv, s.X.shape
    assert np.all(np.isfinite(s.X)), "non-finite coordinates"
    assert s.E.shape == (ne, 2) and (ne == 0 or (s.E.min() >= 0 and s.E.max() < nv))
    if nf:
        idx, _ = edge_index(s.FE)
        assert idx.min() >= 0 and idx.max() < ne
    # (the string model's facets are edge chains and the simplex model's
    # vertex lists, both counted by n_facets)
    n_facets = s.n_facets if getattr(s, "string", False) or getattr(s, "simplex", 0) else nf
    if getattr(s, "simplex", 0):
        assert s.SF.shape == (n_facets, s.simplex + 1)
        assert n_facets == 0 or (s.SF.min() >= 0 and s.SF.max() < nv)
    for attrs, n in ((s.vattr, nv), (s.eattr, ne), (s.fattr, n_facets)):
        for key, arr in attrs.items():
            assert len(arr) == n, (key, len(arr), n)
    b = s.bodies
    if b.n:
        assert b.facet_matrix.shape[0] == b.n
    t = s.evaluate()
    assert isinstance(t.energy, float)


def check_datafile(name, text):
    """Load ``text`` as the datafile ``name`` (reader, builder, first
    evaluation; the read section is not run).  Returns ``"ok"`` or
    ``"error"``; raises :class:`FuzzFailure` otherwise."""
    from pyevolver.errors import DatafileError, PyEvolverError
    from pyevolver.session.core import Session
    try:
        with time_limit(HANG_SECONDS):
            sess = Session.load(name, out=io.StringIO(), err=io.StringIO(), run_read=False,
                                text=text)
    except DatafileError as exc:
        if exc.filename != name or exc.line is None:
            _fail("an unlocated error", name, text, exc)
        first = str(exc).split("\n")[0]
        if not first.startswith(f"{name}:{exc.line}"):
            _fail("a badly located message", name, text, exc)
        return "error"
    except PyEvolverError as exc:
        _fail("an error that is not a located DatafileError", name, text, exc)
    except (Exception, Hang) as exc:
        _fail("a traceback" if not isinstance(exc, Hang) else "a hang", name, text, exc)
    try:
        check_surface(sess.surface)
    except Exception as exc:
        _fail("an invalid surface", name, text, exc)
    return "ok"


def check_parse(text, where):
    """Cut ``text`` into commands and parse each: a located syntax error or
    a command tree.  Returns the number of commands that parsed."""
    from pyevolver.commands import interpreter as I
    from pyevolver.errors import CommandError
    ok = 0
    try:
        with time_limit(HANG_SECONDS):
            I.needs_more(text)
            for chunk, ln in I.split_commands(text):
                try:
                    I.parse_command(chunk, where, ln)
                    ok += 1
                except CommandError as exc:
                    if not str(exc).startswith(f"{where}:"):
                        _fail("an unlocated command error", where, text, exc)
    except FuzzFailure:
        raise
    except (Exception, Hang) as exc:
        _fail("a traceback" if not isinstance(exc, Hang) else "a hang", where, text, exc)
    return ok


def surface_arrays(sess):
    """Copies of the arrays that define the session's surface and settings
    (compared before and after a failing command)."""
    s = sess.surface
    out = {"X": s.X.copy(), "E": s.E.copy(), "FE": s.FE.copy()}
    for name, attrs in (("v", s.vattr), ("e", s.eattr), ("f", s.fattr)):
        for k, a in attrs.items():
            out[f"{name}.{k}"] = np.array(a, copy=True)
    for k, a in s.extra.items():
        out[f"extra.{k}"] = a.copy()
    b = s.bodies
    if b.n:
        out["target"], out["pressure"] = b.target.copy(), b.pressure.copy()
    out["energy"] = np.array(sess.totals.energy)
    out["vars"] = {k: v for k, v in sess.variables.items() if not isinstance(v, np.ndarray)}
    return out


def same_arrays(a, b):
    if a.keys() != b.keys():
        return False
    for k in a:
        if k == "vars":
            if a[k] != b[k] and not _nan_equal(a[k], b[k]):
                return False
        elif a[k].shape != b[k].shape or not np.array_equal(a[k], b[k], equal_nan=True):
            return False
    return True


def _nan_equal(x, y):
    if x.keys() != y.keys():
        return False
    for k in x:
        u, v = x[k], y[k]
        if u != v and not (isinstance(u, float) and isinstance(v, float) and u != u and v != v):
            return False
    return True


def check_commands(sess, text, where):
    """Run ``text`` command by command in ``sess``.  A failing command must
    print a located message and leave the surface as it was (arrays
    compared); nothing may raise a Python exception or hang.  Returns the
    number of commands that failed."""
    from pyevolver.commands import interpreter as I
    from pyevolver.errors import CommandError, InternalError, PyEvolverError
    failed = 0
    try:
        with time_limit(HANG_SECONDS):
            for chunk, ln in I.split_commands(text):
                before = surface_arrays(sess)
                try:
                    sess.run_one(chunk, where, ln)
                except InternalError as exc:
                    _fail("an internal error", where, text, exc.original)
                except PyEvolverError as exc:
                    failed += 1
                    if not str(exc).startswith(f"{where}:"):
                        _fail("an unlocated command error", where, text, exc)
                    if not same_arrays(before, surface_arrays(sess)):
                        _fail("a failing command that changed the surface", where,
                              chunk + "\n--- error: " + str(exc), None)
                except (I.Quit, I.Interrupted):
                    break
            check_surface(sess.surface)
    except FuzzFailure:
        raise
    except (Exception, Hang) as exc:
        _fail("a traceback" if not isinstance(exc, Hang) else "a hang", where, text, exc)
    return failed



@contextlib.contextmanager
def limit(name, value):
    """Set ``pyevolver.limits.<name>`` for the block (small limits keep the
    fuzzed surfaces small and fast)."""
    from pyevolver import limits
    old = getattr(limits, name)
    setattr(limits, name, value)
    try:
        yield
    finally:
        setattr(limits, name, old)


# ---------------------------------------------------------------------------
# hostile input (issue 25): long tokens, deep and flat nesting, huge counts

#: longest hostile token or flat chain (the deep run: 200,000; CI: 2,000)
HOSTILE_MAX = 2_000


def _long(rng):
    """A length: mostly short, now and then up to :data:`HOSTILE_MAX`."""
    if rng.random() < 0.03:
        return rng.choice([n for n in (1000, 10_000, 50_000, 200_000) if n <= HOSTILE_MAX]
                          or [HOSTILE_MAX])
    return rng.randrange(1, 200)


def long_token(rng):
    """A digit run ended by a letter, a dot or an exponent, a long name, a
    long string, a long comment, a long run of one punctuation character."""
    n = _long(rng)
    k = rng.randrange(8)
    if k == 0:
        return "1" * n + rng.choice(["a", ".", "e", "e+", "..", "d-", "x", ""])
    if k == 1:
        return "." + "5" * n + rng.choice([".", "e", "q"])
    if k == 2:
        return "a" * n
    if k == 3:
        return '"' + "s" * n + rng.choice(['"', ""])
    if k == 4:
        return "/*" + "*" * n + rng.choice(["*/", ""])
    if k == 5:
        return rng.choice("+-*/(){}[],;:=<>!&|#\\") * n
    if k == 6:
        return " \t" * n + "1"
    return "1e" * (n // 2 + 1)


def flat_chain(rng):
    """A flat expression of up to 100,000 terms (``1+1+...``, mixed operators)."""
    n = rng.choice([n for n in (1000, 10_000, 100_000) if n <= HOSTILE_MAX] or [HOSTILE_MAX]) \
        if rng.random() < 0.02 else rng.randrange(2, 300)
    ops = rng.choice([["+"], ["-"], ["*", "/"], ["+", "-", "*"], ["^"], ["==", "<"], ["&&"]])
    return "1" + "".join(rng.choice(ops) + "1" for _ in range(n))


HUGE_COUNTS = ["1e9", "1e18", "2^62", "1e308", "99999999999", "-1e9", "1e400", "0"]


def hostile_command(rng):
    """A command with a long token, deep or flat nesting or a huge count."""
    k = rng.randrange(6)
    if k == 0:
        return f"print {long_token(rng)}"
    if k == 1:
        return f"print {flat_chain(rng)}"
    if k == 2:
        return f"print {_deep(rng)}" if rng.random() < 0.5 else _deep(rng)
    if k == 3:
        c = rng.choice(HUGE_COUNTS)
        return rng.choice([f"g {c}", f"r {c}", f"define arr real[{c}]", f"define arr real[{c}][{c}]",
                           f"u {c}", f"V {c}", f"hessian_seek {c}", f"{{ aa := 1 }} {c}",
                           f"vertex[{c}].x := 1", f"refine edge[{c}]", f"list vertex[{c}]",
                           f"printf \"%{c}d\", 1", f"print sprintf(\"%.{c}f\", 1)",
                           f"aa := {c}; while aa > 0 do aa := aa - 1"])
    if k == 4:
        return f"aa := {long_token(rng)}" if rng.random() < 0.5 else \
            f"{long_token(rng)} := 1"
    return random_command(rng) + " " + long_token(rng)


def hostile_datafile(text, rng):
    """``text`` with a long token, deep or flat nesting or a huge count put
    at a random token."""
    toks = tokens(text)
    words = _words(toks) or [0]
    k = rng.choice(words) if toks else 0
    pick = rng.randrange(4)
    piece = [long_token, flat_chain, _deep, lambda r: r.choice(HUGE_COUNTS)][pick](rng)
    if not toks:
        return piece
    toks[k] = piece if rng.random() < 0.7 else toks[k] + piece
    return "".join(toks)
