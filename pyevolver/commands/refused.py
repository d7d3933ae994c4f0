"""Commands refused by name: Evolver commands pyevolver does not have yet
(``e``, ``hessian_menu``, ``detorus``, ...), ``abort``, and the statements the
grammar marks unsupported (``system``, ``permload``, ...).  They fail with
an :class:`~pyevolver.errors.UnsupportedError` (or ``abort``'s message)
rather than as unknown words.
"""
from __future__ import annotations

from ..errors import CommandError, UnsupportedError
from .registry import register

LETTER_LATER = {
    "g": "g (iteration)",
    "U": "U (conjugate gradient)",
    "m": "m (fixed scale)",
    "G": "G (gravity)",
    "e": "e (extrapolation)", "i": "i (information)", "Q": "Q (quantities)",
    "C": "C (consistency check)", "c": "c (counts)", "N": "N",
    "b": "b (interactive body targets)", "p": "p (ideal gas)", "y": "y (torus duplication)",
    "Z": "Z (zoom)", "J": "J (jiggle toggle)",
}
WORD_LATER = {
    "hessian_menu", "move",
    "vertex_average", "raw_vertex_average", "rawest_vertex_average",
    "t1_edgeswap", "dissolve", "optimize", "optimise",
    "jiggle", "extrapolate", "counts", "check", "show_vol_later", "detorus", "runge_kutta",
    "conj_grad_later", "fix", "unfix", "burchard", "zoom",
}


@register("abort", usage="abort", statement="abort", help="stop the command with an error",
          family="refused")
def _x_abort(interp, node):
    raise CommandError("Command aborted (abort).")


@register("system", "shell", "permload", "define boundary", "define quantity",
          "define method_instance", "detorus", "dissolve", "binary_printf",
          "binary_off_file", "postscript", "reorder_storage", "renumber_all",
          usage="(refused)", statement="unsupported", help="refused by name",
          family="refused")
def _x_unsupported(interp, node):
    raise UnsupportedError(*node[1:])


def _letter_later(interp, raw, arg):
    raise UnsupportedError(f"command {LETTER_LATER[raw]}")


def _word_later(interp, raw, arg):
    raise UnsupportedError(f"command {raw.lower()}")


register(*sorted(LETTER_LATER), usage="(refused)", help="not implemented yet",
         family="refused", replace=False)(_letter_later)
register(*sorted(WORD_LATER), usage="(refused)", help="not implemented yet",
         family="refused", replace=False)(_word_later)
