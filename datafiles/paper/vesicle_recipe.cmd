// vesicle_recipe.cmd: the Evolver's smoothing recipe for the Canham vesicles
// of the PL-methods paper's Figure 4 (datafiles/paper/vesicle_*_perp.fe).
// Runs unchanged in pyevolver and in the Surface Evolver 2.70:
//
//     pyevolver vesicle_prolate_perp.fe -f vesicle_recipe.cmd
//     evolver-nox-d -f vesicle_recipe.cmd vesicle_prolate_perp.fe
//
// then at the prompt `relax` converges at the current resolution, `r`
// refines; `fig4_levels := 2; fig4` does 162 -> 642 -> 2562 vertices and
// prints one FIG4 line per resolution:
//     FIG4 vertices W area volume cycles clock
// (W = willmore.value = sum over vertices of h^2 A/3, a sphere has 4*pi).
//
// A cycle is vertex averaging (V), equiangulation (u) and recipe_g
// gradient steps; cycles repeat until one changes the energy by less than
// recipe_tol times the energy (at most recipe_max cycles per resolution).
// V and u keep the triangles healthy; the g batch relaxes what V disturbed.
// (V pulls the vertices towards an even spread that is not W's optimum, so
// the energy may rise from cycle to cycle: the recipe converges to the
// fixed point of a cycle, not to a minimum of W.)

recipe_g := 20
recipe_tol := 1e-6
recipe_max := 200

cycle := { V; u; g recipe_g }

relax := {
    g recipe_g;
    recipe_cycles := 0;
    do {
        recipe_old := total_energy;
        cycle;
        recipe_cycles := recipe_cycles + 1
    } while (abs(recipe_old - total_energy) > recipe_tol * abs(total_energy)
             and recipe_cycles < recipe_max)
}

report := {
    printf "FIG4 %d %.15g %.15g %.15g %d %.6f\n", vertex_count, willmore.value,
        total_area, body[1].volume, recipe_cycles, clock
}

fig4_levels := 2
fig4 := {
    relax;
    report;
    fig4_level := 0;
    while fig4_level < fig4_levels do {
        r;
        relax;
        report;
        fig4_level := fig4_level + 1
    }
}
