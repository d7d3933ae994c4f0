"""Start-up (pyevolver/startup.py and the lazy imports of issue 24): what
``pyevolver cube.fe`` imports, and that the lazily imported modules still
work when used.  Each check runs in a fresh interpreter (two in all, to
keep the suite fast)."""
import os
import subprocess
import sys

import numpy

from pyevolver.startup import LAZY_SUBMODULES, lazy_numpy_submodules

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

HEAVY = ["meshio", "scipy.sparse.linalg", "scipy.linalg", "numpy.f2py.crackfortran", "unittest",
         "scipy.sparse.csgraph", "scipy.sparse._csr", "scipy._lib", "regex._regex_core",
         "numpy.random._generator",
         # pyevolver's Hessian, pictures and viewer: imported where first used
         "pyevolver.evolve.hessian", "pyevolver.evolve.eigen", "pyevolver.evolve.newton",
         "pyevolver.evolve.bfgs", "pyevolver.io.render", "pyevolver.io.viewer", "pyevolver.io.movie"]

USE = ("import numpy as np\n"
       "print(np.random.default_rng(0).integers(10, size=3).tolist())\n"
       "np.testing.assert_allclose(1.0, 1.0)\n"
       "from numpy.fft import rfft\n"
       "print(rfft([1.0, 1.0]).real.tolist())\n"
       "m = meshio.read('datafiles/cube.fe')\n"
       "print(meshio.extension_to_filetypes['.fe'], len(m.cells_dict['triangle']))\n"
       "import scipy.sparse as sp\n"
       "import scipy.sparse.linalg\n"
       "import scipy\n"
       "from scipy import linalg\n"
       "print(linalg.det(np.eye(2)), scipy.__version__ == sys.modules['scipy'].__version__)\n"
       "import importlib.util, lark\n"
       "print(lark.Lark(r'start: /\\p{L}+/', parser='lalr', regex=True).parse('ab').children\n"
       "      if importlib.util.find_spec('regex') else \"[Token('__ANON_0', 'ab')]\")\n"
       "print(sp.csr_matrix(np.eye(3)).nnz, sp.linalg.norm(sp.eye(4)) ** 2, sys.modules['scipy.sparse'] is"
       " sys.modules['scipy'].sparse, isinstance(sp.eye(2), sys.modules['scipy.sparse'].spmatrix))\n")


def _run(code, **env_extra):
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT
    env.update(env_extra)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       cwd=ROOT, timeout=120)
    assert p.returncode == 0, p.stderr
    return p.stdout.splitlines()


def test_load_and_quit_imports_no_heavy_optional_modules_that_work_when_used():
    out = _run("import io, sys\n"
               "import pyevolver.cli.main\n"
               "from pyevolver import Session, startup\n"
               "Session.load('datafiles/cube.fe', out=io.StringIO())\n"
               f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules) or 'none')\n"
               "print(startup.lazy_numpy_submodules())\n"      # a second call: nothing
               "import meshio\n" + USE)
    assert out[0] == "none"
    assert out[1] == "[]"
    # the same numbers and the .fe format for meshio imported first, without
    # the lazy numpy modules (numpy's own import on scipy's first use)
    ref = _run("import sys, meshio, pyevolver, scipy.sparse\nfrom pyevolver import startup\n"
               "print('numpy.f2py' in sys.modules, startup.lazy_numpy_submodules())\n" + USE,
               PYEVOLVER_LAZY_NUMPY="0", PYEVOLVER_LAZY_SCIPY="0")
    assert ref[0] == "True []"
    assert out[2:] == ref[1:]
    assert out[3:] == ["[2.0, 0.0]", "['evolver'] 24", "1.0 True", "[Token('__ANON_0', 'ab')]",
                       "3 4.0 True True"]


def test_registered_once_and_only_numpys_optional_submodules():
    # (this process imported pyevolver: the call at import was the first)
    assert lazy_numpy_submodules() == []
    for short in LAZY_SUBMODULES:
        assert f"numpy.{short}" in sys.modules and getattr(numpy, short) is \
            sys.modules[f"numpy.{short}"]
