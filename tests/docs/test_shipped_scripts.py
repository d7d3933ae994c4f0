"""Shipped command scripts beyond the exporters, run in both programs.

Each case reads scripts from /usr/share/doc/evolver/examples, runs their
commands on a datafile in evolver-nox-d and in pyevolver, and compares what
they print (numbers within 1e-10) and the files they write (byte for byte).
"""
import os
import shutil

import pytest

from conftest import EXAMPLES, example
from comparison import _same
from comparison import _run_both

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
MEMORY = ("Element memory", "Total data memory")
BRACES = str.maketrans("{},", "   ")

CASES = {
    # cut.cmd and simply_connected.cmd (seams of a closed and of an open
    # surface), complex.cmd's functions, rotate.cmd, gaussmap.cmd (its list
    # shows the defined attributes), show_equi/equi2/gaussequi, slice.cmd,
    # xray.cmd (PostScript file) and dxf_thick.cmd (vertex normals as arrays)
    "cube": ("cube.fe", """read "cut.cmd"
cut
foreach edge ee where ecutmark do printf "%d ", ee.id
printf "\\n"
read "simply_connected.cmd"
mark_distances
mark_simply_connected
foreach edge ee do printf "%d:%d:%d ", ee.id, sc_emark, color
printf "\\n"
foreach facet ff do printf "%d:%d:%d ", ff.id, sc_fdistance, color
printf "\\n"
read "complex.cmd"
printf "%.15g %.15g\\n", re_sqrt(-2, 0.5), im_sqrt(-2, 0.5)
printf "%.15g %.15g\\n", re_sin(0.7, 1.3), im_sin(0.7, 1.3)
printf "%.15g %.15g\\n", re_arcsin(-1.7, -0.9), im_arcsin(-1.7, -0.9)
printf "%.15g %.15g\\n", re_incompleteEllipticF(0.8, 0.4, 0.3, 0, 0), im_incompleteEllipticF(0.8, 0.4, 0.3, 0, 0)
printf "%.15g %.15g\\n", re_incompleteEllipticF(2.5, -0.6, 0.5, 3, 1), im_incompleteEllipticF(2.5, -0.6, 0.5, 3, 1)
read "dxf_thick.cmd"
dxf_thickness := 0.02
dxf_thick >>> "thick.dxf"
read "xray.cmd"
xgridsize := 24
ygridsize := 20
xray >>> "xray.ps"
r
g 3
read "show_equi.cmd"
show_equi
read "equi2.cmd"
showequi
foreach edge ee where color != 0 do printf "%d %d\\n", id, color
read "gaussequi.cmd"
gaussequi
read "slice.cmd"
slice
read "rotate.cmd"
rotate(0.3)
read "gaussmap.cmd"
gaussmap
list vertices
""", ["thick.dxf", "xray.ps"]),
    # dirichlet_to_disk.cmd: run-time `define constraint`, boundary walk,
    # `set ... constraint name`, hessian with no energy on the free vertices
    "disk": ("quad.fe", 'read "dirichlet_to_disk.cmd"\nr\nto_disk\nlist vertices\nlist edges\n', []),
    "triangle": ("quad.fe", 'read "dirichlet_to_disk.cmd"\nr\nto_triangle\nlist vertices\n'
                            'foreach facet ff do printf "%g %g %g\\n", ff.form_factors[1], '
                            'ff.form_factors[2], ff.form_factors[3]\n', []),
    # adjoint.cmd (Polthier's conjugate surface; autodisplay toggle) and
    # band.cmd on quad.fe
    "adjoint": ("quad.fe", 'read "adjoint.cmd"\nr\nr\ng 10\nadjoint\nlist vertices\n'
                           'read "band.cmd"\nbandcolor := red\nbandwidth := 0.1\nmakeband\n'
                           'print facet_count\n', []),
    # foamface.cmd on the torus foam (frontbody/backbody)
    "foam": ("twointor.fe", 'read "foamface.cmd"\nfoamface_mark\nfoamface_min\nfoam_signature\n',
             []),
    # strings: zebra.cmd and fourier.cmd
    "zebra": (os.path.join(DATA, "string_circle.fe"),
              'read "zebra.cmd"\nzebra\nforeach edge ee do printf "%d %d\\n", id, color\n', []),
    "fourier": (os.path.join(DATA, "string_loop3.fe"),
                'read "fourier.cmd"\nf_component(1)\nf_component(2)\nf_component(3)\n', []),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_shipped_script(evolver, case, tmp_path):
    name, script, files = CASES[case]
    datafile = name if os.path.isabs(name) else example(name)
    dirs, ref, out, err = _run_both(evolver, datafile, script, tmp_path)
    assert err == ""
    # array attributes print as {a,b,c}: compare their numbers one by one
    ref = [l.translate(BRACES) for l in ref if l.strip() and not l.startswith(MEMORY)]
    out = [l.translate(BRACES) for l in out if l.strip()]
    assert _same(out, ref, 1e-10), (out, ref)
    for f in files:
        a, b = dirs["ref"] / f, dirs["ours"] / f
        assert a.stat().st_size > 0
        assert a.read_bytes() == b.read_bytes(), f


@pytest.mark.parametrize("script, run, word", [
    ("edge_tuber.cmd", "set edge tuber_status tuber_edge_to_do where id < 3\nedge_tuber(0.1)",
     "new_vertex"),
    ("detorus_capper.cmd", "", "array elements in constraint formulas"),
    ("slicer.cmd", "slicer", "frontbody"),
    ("3ds.cmd", "", "syntax error"),
])
def test_scripts_refused_by_name(script, run, word, tmp_path):
    """Scripts that need what pyevolver does not have stop with a message
    that names it (and leave the surface as it was)."""
    import io
    from pyevolver import Session
    shutil.copy(os.path.join(EXAMPLES, script), tmp_path)
    out, err = io.StringIO(), io.StringIO()
    s = Session.load(example("cube.fe"), out=out, err=err)
    X = s.surface.X.copy()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        s.run(f'read "{script}"\n{run}\n', stop_on_error=False)
    finally:
        os.chdir(cwd)
    assert word in err.getvalue()
    assert (s.surface.X == X).all()
