"""The toggles of the command language (``quiet``, ``conj_grad on``,
``gravity off``, every toggle of the manual's toggle.htm) and the words that
name graphics commands.

:func:`toggle` runs ``NAME``, ``NAME on``, ``NAME off``, ``NAME expr``;
the tables say how REF names each toggle in its ``NAME ON. (was off)``
message, which toggles share one state, and which ones are refused when
turned on.
"""
from __future__ import annotations

from ..errors import UnsupportedError
from ..expr import nodes as N
from .registry import register
from .values import is_true

TOGGLES = {
    "conj_grad", "check_increase", "autopop", "autochop", "quiet", "quietgo",
    "hessian_normal", "normal_motion", "area_normalization", "effective_area",
    "normal_curvature", "assume_oriented", "autorecalc", "estimate", "volgrads_every",
    "verbose", "ribiere", "approximate_curvature", "rgb_colors", "runge_kutta", "kraynikpopvertex",
    "kraynikpopedge", "hessian_diff", "linear_metric", "post_project", "gravity",
    "keep_macros", "brief", "itdebug", "memdebug", "visibility_test", "clipped",
    "connected", "thicken", "smooth_graph", "pscolorflag", "gridflag", "crossingflag",
    "labelflag", "self_similar", "pinning", "diffusion", "sqgauss", "interp_bdry_param",
    "h_inverse_metric", "jiggle", "break_after_warning", "full_bounding_box",
    "show_all_quantities", "show_inner", "show_outer", "colormap", "bezier_basis",
    "volgrads_every", "zener_drag", "backcull", "debug", "autodisplay",
    "hessian_backtrack",     # pyevolver's own: hessian halves a step that raises the energy
}
GRAPHICS = {"s", "P", "show", "show_expr", "transform_expr", "geomview",
            "postscript", "showq", "view_transforms", "ps", "oogl", "gv", "screen"}
TOGGLE_DEFAULTS = {"hessian_normal": 1, "autorecalc": 1, "ribiere": 1}
# how REF names a toggle in "NAME ON. (was off)" (measured; the others use
# their own name)
TOGGLE_WORDS = {
    "check_increase": "Increase check", "conj_grad": "Conjugate gradient now",
    "ribiere": "Polak-Ribiere conjugate gradient", "gravity": "Gravity",
    "normal_motion": "Normal motion", "area_normalization": "Area normalization",
    "autorecalc": "Autorecalc", "estimate": "Estimation", "volgrads_every": "Volgrads_every",
    "verbose": "Verbose", "rgb_colors": "RGB colors", "runge_kutta": "Runge-Kutta",
    "kraynikpopvertex": "Kraynik pop vertex mode", "kraynikpopedge": "Kraynik pop edge mode",
    "post_project": "Post-projection", "visibility_test": "visibility test",
    "smooth_graph": "smooth graph", "self_similar": "Self similarity mode",
    "pinning": "Constraint pinning", "diffusion": "Diffusion",
    "sqgauss": "Squared Gaussian curvature", "jiggle": "jiggling",
    "break_after_warning": "Break after warning", "show_inner": "show inner",
    "show_outer": "show outer", "memdebug": "Memory debugging", "autodisplay": "Autodisplay",
}

# -- every toggle of the manual (toggle.htm) -------------------------------------
# The rest of the list; REF's synonyms share one state.
TOGGLES |= {
    "ambient_pressure", "approx_curv", "augmented_hessian", "autopop_quartic", "big_endian",
    "little_endian", "blas_flag", "boundary_curvature", "break_on_warning", "bunch_kaufman",
    "bunch_kauffman", "calculate_in_3d", "circular_arc_draw", "clip_view", "clipped_cells",
    "connected_cells", "raw_cells", "conf_edge", "detorus_sticky", "deturck", "dirichlet_mode",
    "sobolev_mode", "facet_colors", "force_deletion", "force_edgeswap",
    "function_quantity_sparse", "gv_binary", "hessian_double_normal", "hessian_normal_one",
    "hessian_normal_perp", "hessian_quiet", "hessian_special_normal", "homothety",
    "immediate_autopop", "interp_normals", "k_altitude_mode", "kusner", "metric_conversion",
    "metric_convert", "old_area", "pop_disjoin", "pop_enjoin", "pop_to_edge", "pop_to_face",
    "ps_cmykflag", "ps_colorflag", "ps_crossingflag", "ps_gridflag", "ps_labelflag",
    "quantities_only", "quietload", "rotate_lights", "septum_flag", "shading", "show_all_edges",
    "show_bounding_box", "slice_view", "sparse_constraints", "squared_gradient",
    "star_finagling", "torus_filled", "transforms", "view_4d",
    "view_transforms_use_unique_point", "ysmp",
}
# synonyms -> the name REF stores the state under
TOGGLE_ALIASES = {
    "approx_curv": "approximate_curvature", "metric_convert": "metric_conversion",
    "clipped_cells": "clipped", "connected_cells": "connected",
    "bunch_kauffman": "bunch_kaufman", "ps_crossingflag": "crossingflag",
    "gridflag": "ps_gridflag", "labelflag": "ps_labelflag", "pscolorflag": "ps_colorflag",
}
# initial states other than off (measured: print NAME after loading); -1 is "unset"
TOGGLE_DEFAULTS.update({
    "detorus_sticky": 1, "facet_colors": 1, "function_quantity_sparse": 1, "hessian_quiet": 1,
    "kraynikpopvertex": 1, "little_endian": 1, "shading": 1, "show_all_edges": 1,
    "show_inner": 1, "show_outer": 1, "sparse_constraints": 1, "transforms": 1, "raw_cells": 1,
    "augmented_hessian": -1, "crossingflag": -1, "ps_crossingflag": -1,
    "ps_colorflag": -1, "pscolorflag": -1, "ps_gridflag": -1, "gridflag": -1,
    "ps_labelflag": -1, "labelflag": -1, "septum_flag": -1,
})
TOGGLE_WORDS.update({
    "approximate_curvature": "approx_curvature", "augmented_hessian": "augmented Hessian",
    "boundary_curvature": "Boundary curvature", "break_on_warning": "Break on warning",
    "bunch_kaufman": "Bunch-Kaufman version of minimal degree",
    "circular_arc_draw": "Circular arc drawing", "conf_edge": "Conformal edge square curvature",
    "facet_colors": "Facet colors", "gv_binary": "Geomview binary mode",
    "k_altitude_mode": "K altitude mode", "kusner": "Edge square curvature",
    "metric_conversion": "Metric conversion", "quietload": "QuietLoad",
    "shading": "Facet shading", "sparse_constraints": "sparse constraints",
    "transforms": "Transform showing", "view_transforms_use_unique_point":
    "view_transforms_use_unique", "dirichlet_mode": "Dirichlet area mode",
    "sobolev_mode": "Sobolev area mode", "ps_gridflag": "ps_gridflag",
    "ps_labelflag": "ps_labelflag", "ps_colorflag": "ps_colorflag",
})
# REF's message when the generic "WORD ON. (was off)" does not fit: (on, off)
# formats with {was} ("on", "off" or "unset"), {WAS} (upper case), {WAS_}
# ("OFF." and a line break, or "ON."), {alg} (ysmp) and {zener} (zener_coeff)
TOGGLE_MESSAGES = {
    "autopop": ("Autopopping ON.\n (was {was})\n", "Autopopping OFF.\n (was {was})\n"),
    "autopop_quartic": ("Autopop quartic mode ON.\n (was {was})\n",
                        "Autopop quartic mode OFF.\n (was {was})\n"),
    "immediate_autopop": ("Immediate autopop mode ON.\n (was {was})\n",
                          "Immediate autopop mode OFF.\n (was {was})\n"),
    "debug": ("YACC debugging was {WAS_}Now ON.\n", "YACC debugging was {WAS_}Now OFF.\n"),
    "itdebug": ("Iteration debugging was {WAS_}Now ON.\n",
                "Iteration debugging was {WAS_}Now OFF.\n"),
    "ysmp": ("Using YSMP. (was {alg})\n", "Using alternate minimal degree. (was {alg})\n"),
    "interp_bdry_param": ("interpolation of boundary parameters  ON. (was {was})\n",
                          "interpolation of boundary parameters OFF (using extrapolation). "
                          "(was {was})\n"),
    "linear_metric": ("Linear interpolation metric with Hessian ON.(was {WAS})\n",
                      "Linear interpolation metric with Hessian OFF.(was {WAS})\n"),
    "quantities_only": ("Using quantities only ON.(was {WAS})\n",
                        "Using quantities only OFF.(was {WAS})\n"),
    "squared_gradient": ("Squared gradient minimization with Hessian ON.(was {WAS})\n",
                         "Squared gradient minimization with Hessian OFF.(was {WAS})\n"),
    "ambient_pressure": ("", "Ambient pressure OFF.\n"),
    "view_4d": ("4D graphics  ON. (was {was})\n", "4D graphics  OFF. (was {was})\n"),
    "zener_drag": ("", "Zener_drag OFF. (was {was})  ({zener})\n"),
}
for _name in ("bezier_basis", "hessian_normal", "hessian_normal_one", "hessian_normal_perp",
              "hessian_quiet", "hessian_double_normal"):      # two spaces before ON
    TOGGLE_MESSAGES[_name] = (_name + "  ON. (was {was})\n", _name + " OFF. (was {was})\n")
# toggles REF switches without a word
TOGGLE_SILENT = {"colormap", "connected", "thicken", "raw_cells", "interp_normals"}
# graphics display of the torus model: one of three modes
TOGGLE_CELLS = ("clipped", "connected", "raw_cells")
# toggles that change numbers in a model pyevolver supports but are not
# implemented: refused when turned on (off is their initial state)
TOGGLE_REFUSED = {
    "ambient_pressure": "the ideal gas model is not implemented",
    "boundary_curvature": "the boundary star rule of the curvature integrals is not "
                          "implemented",
    "conf_edge": "the conformal edge formula of squared curvature is not implemented",
    "kusner": "the edge formula of squared curvature is not implemented",
    "deturck": "unit normal motion is not implemented",
    "dirichlet_mode": "the Dirichlet area Hessian is not implemented",
    "sobolev_mode": "the Sobolev area Hessian is not implemented",
    "homothety": "homothety scaling is not implemented",
    "hessian_special_normal": "HESSIAN_SPECIAL_NORMAL_VECTOR is not supported",
    "hessian_double_normal": "the Hessian normal variants are not implemented",
    "hessian_normal_one": "the Hessian normal variants are not implemented",
    "hessian_normal_perp": "the Hessian normal variants are not implemented",
    "squared_gradient": "squared gradient minimization is not implemented",
    "quantities_only": "switching off the energies other than named quantities is not "
                       "implemented",
    "zener_drag": "Zener drag is not implemented",
    "force_deletion": "delete keeps its checks", "star_finagling": "delete keeps its checks",
    "force_edgeswap": "edgeswap keeps its checks",
    "pop_disjoin": "the pop variants are not implemented",
    "pop_enjoin": "the pop variants are not implemented",
    "pop_to_edge": "the pop variants are not implemented",
    "pop_to_face": "the pop variants are not implemented",
    "septum_flag": "the pop variants are not implemented",
    "k_altitude_mode": "K (skinny triangle refinement) uses the median",
}


def graphics_toggle(tok):
    """A display word of the command grammar that is also a toggle
    (``transforms off``, ``clipped on``, ``ps_colorflag``): the toggle command,
    or None for a graphics command."""
    words = str(tok).split()
    if not words or words[0].lower() not in TOGGLES or len(words) > 2:
        return None
    if len(words) == 2 and words[1].lower() not in ("on", "off"):
        return None
    arg = N.Var(words[1].lower()) if len(words) == 2 else None
    return ("bare", words[0].lower(), arg)



def toggle(interp, name, arg):
    """Run the toggle ``name`` with its argument node ``arg`` (None: on)."""
    s = interp.session
    if name in ("conj_grad", "ribiere"):      # both erase the CG history (REF)
        s.reset_cg()
    if arg is None:
        new = 1
    elif isinstance(arg, N.Var) and arg.name in ("on", "off"):
        new = 1 if arg.name == "on" else 0
    else:
        v = interp.value(arg)
        new = (1 if v else 0) if isinstance(v, str) else int(is_true(v, "a toggle value"))
    key = TOGGLE_ALIASES.get(name, name)
    names = [key] + [a for a, k in TOGGLE_ALIASES.items() if k == key]
    default = TOGGLE_DEFAULTS.get(key, 0)
    if key == "show_all_edges" and s.surface is not None and s.surface.string:
        default = 0                         # REF: off in the string model
    old = s.toggles.get(key, default)
    if name == "autopop" and new and s.surface is not None and not s.surface.string:
        raise UnsupportedError("autopop in the soapfilm model",
                               "only the string model's popping is implemented")
    if key in TOGGLE_REFUSED and new:
        raise UnsupportedError(f"{name} on", TOGGLE_REFUSED[key])
    surf = s.surface
    torus = surf is not None and surf.periods is not None
    if key == "blas_flag":                   # REF's build has no BLAS either
        s.write_err("WARNING 2472: This Evolver not compiled with BLAS.\n")
        return
    if key == "torus_filled":
        if not torus:
            s.write_err("WARNING 2042: torus_filled is invalid toggle because not in "
                        "torus model.\n")
            return
        if new != old:
            raise UnsupportedError(f"torus_filled {'on' if new else 'off'} at run time",
                                   "the torus_filled model is fixed by the datafile")
    if key == "calculate_in_3d" and new and surf is not None and surf.sdim > 3:
        raise UnsupportedError("calculate_in_3d on", "curvature in the first three "
                               "coordinates is not implemented")
    for n in names:
        s.toggles[n] = new
    if key == "effective_area":          # the command also changes REF's motion
        s.toggles["_effective_area_motion"] = new
    if key in TOGGLE_CELLS:                  # one display mode of three
        for other in TOGGLE_CELLS:
            if other != key:
                for n in [other] + [a for a, k in TOGGLE_ALIASES.items() if k == other]:
                    s.toggles[n] = 0
        if key == "clipped" and not torus:
            s.write_err("WARNING 1254: CLIPPED mode has no effect since torus model not "
                        "used.\n")
        return
    if key == "big_endian" and new:
        s.toggles["little_endian"] = 0
    elif key == "little_endian" and new:
        s.toggles["big_endian"] = 0
    was = {1: "on", 0: "off"}.get(old, "unset")
    now = "ON" if new else "OFF"
    if key in TOGGLE_SILENT:
        pass
    elif key == "quietgo":               # REF prints this one even when quiet
        s.write(f"QuietGo {now}. (was {was})\n")
    elif key == "quiet":
        if not new:                     # turning it on is silent
            s.write(f"Quiet OFF. (was {was})\n")
    elif key == "autochop":
        if new:
            s.note(f"Autochopping ON. Chop length {s.settings.get('autochop_length', 0.0):g}"
                   f"  (was {was})\n"
                   "Set autochop length with  AUTOCHOP_LENGTH := value\n")
        else:
            s.note(f"Autochopping OFF. (was {was})\n")
    elif key in TOGGLE_MESSAGES:
        fmt = TOGGLE_MESSAGES[key][0 if new else 1]
        zc = s.variables.get("zener_coeff")
        if key == "ysmp" and new == old:      # REF says nothing then
            fmt = ""
        s.note(fmt.format(was=was, WAS=was.upper(),
                          WAS_="OFF.\n" if old == 0 else was.upper() + ".",
                          alg="YSMP" if old else "alt min deg",
                          zener="zener_coeff not set" if zc is None else
                          f"zener_coeff: {zc:g}" if isinstance(zc, (int, float))
                          else "zener_coeff"))
    else:
        word = TOGGLE_WORDS.get(key, key)
        s.note(f"{word} {now}. (was {was})\n")
    if key == "sparse_constraints" and not new:     # REF settles an unset one too
        old_aug = s.toggles.get("augmented_hessian", TOGGLE_DEFAULTS["augmented_hessian"])
        if old_aug == -1:
            s.toggles["augmented_hessian"] = 0
            s.note("augmented Hessian OFF. (was unset)\n")
    if key == "gravity":
        s.recalc()


# -- registration ---------------------------------------------------------------------
def _graphics(interp, raw, arg):
    """Graphics commands draw nothing here (no display)."""
    return


register(*sorted(n for n in GRAPHICS if len(n) > 1), "s", "S", "P",
         usage="s | show | geomview | ...", help="graphics (nothing is drawn)",
         family="toggles")(_graphics)


def _toggle_command(interp, raw, arg):
    toggle(interp, raw.lower(), arg)


register(*sorted(TOGGLES), usage="NAME [on|off]", help="a toggle of the manual (toggle.htm)",
         family="toggles", replace=False)(_toggle_command)
