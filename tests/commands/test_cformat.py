"""Direct tests of pyevolver.commands.cformat: C printf semantics and the
``print`` layouts, against the reference Evolver run live."""
import os

import numpy as np
import pytest

from pyevolver.commands.cformat import c_format, print_array, print_value
from pyevolver.errors import CommandError

from reference import run_reference

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")

# (format, argument expressions as the Evolver reads them, the same values for c_format)
CASES = [
    ("%g %10.4f\\n", "1/3, 2", [1 / 3, 2.0]),
    ("%5d|%-6.2e|%x|%o\\n", "42.9, 12345.678, 255, 8", [42.9, 12345.678, 255.0, 8.0]),
    ("%s and %c\\n", '"abc", 65', ["abc", 65.0]),
    ("%+.3e %08.3f %%\\n", "-2.5, 3.14159", [-2.5, 3.14159]),
    ("%d %5d\\n", "-7.9, 7.9", [-7.9, 7.9]),
]


def test_c_format_matches_reference_printf(evolver):
    script = "".join(f'printf "{fmt}", {args}\n' for fmt, args, _ in CASES)
    ref = run_reference(evolver, CUBE, script)
    ours = "".join(c_format(fmt.replace("\\n", "\n"), vals) for fmt, _, vals in CASES)
    assert [l for l in ref if l.strip()] == [l for l in ours.split("\n") if l]


def test_print_value_matches_reference_print(evolver):
    ref = run_reference(evolver, CUBE, "print 1/3\nprint 7\nprint -2.5e-7\n")
    ours = [print_value(1 / 3), print_value(7.0), print_value(-2.5e-7)]
    assert [l for l in ref if l.strip()] == ours
    assert print_value(7) == "7"            # integer-typed values print as integers
    assert print_value("text") == "text"


def test_c_semantics_star_width_and_truncation():
    # negative '*' width: left-justified; conversion to int truncates toward zero
    assert c_format("%*d|", [-5, 3]) == "3    |"
    assert c_format("%*d|", [4, 3]) == "   3|"
    assert c_format("%.*f", [2, 3.14159]) == "3.14"
    assert c_format("%d %d", [2.99, -2.99]) == "2 -2"
    # negative numbers in %x are unsigned 32-bit
    assert c_format("%x", [-1]) == "ffffffff"
    assert c_format("100%%", [1]) == "100%"


def test_c_format_errors():
    with pytest.raises(CommandError, match="not enough arguments"):
        c_format("%g %g", [1.0])
    with pytest.raises(CommandError, match="string"):
        c_format("%f", ["abc"])
    with pytest.raises(CommandError, match="array"):
        c_format("%g", [np.zeros(3)])
    assert c_format("%g", [np.array([2.5])]) == "2.5"


def test_print_array_matches_reference(evolver):
    ref = run_reference(evolver, CUBE, "define arr real[2][2]; arr[1][1] := 1; arr[2][2] := 4; "
                        "arr[1][2] := 1/3; print arr\n"
                        "define iv integer[2]; iv[1] := 3; iv[2] := -4; print iv\n")
    ours = (print_array(np.array([[1.0, 1 / 3], [0.0, 4.0]])) + "\n"
            + print_array(np.array([3, -4], dtype=int)))
    assert [l for l in ref if l.strip()] == ours.split("\n")
