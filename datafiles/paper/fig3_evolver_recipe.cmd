// The Evolver's own recipe for squared-mean-curvature energies (the paper's
// Figure 3 comparison): batches of gradient steps (g) interleaved with vertex
// averaging (V), equiangulation (u) and notching (n).  Runs unchanged in
// pyevolver and in Surface Evolver 2.70 on the files without harmonic_energy:
//
//     pyevolver torus10x16_offset_normal.fe -f fig3_evolver_recipe.cmd
//     evolver -f fig3_evolver_recipe.cmd torus10x16_offset_normal.fe
//
// The vertices are first moved by about 1e-3 by a fixed formula (the same
// in both programs): the exact grid is symmetric, and equiangulation breaks
// ties between co-circular edges differently in the two programs.
// One line per round: round, vertices, W (the quantity willmore), smallest
// facet angle in degrees, clock (seconds since the program started).
// To change the schedule run  recipe(rounds, gsteps)  yourself.

// smallest angle of a triangle with sides e1, e2, e3, in degrees
function real cornermin(real e1, real e2, real e3) {
  local a1, a2;
  a1 := acos((e2^2 + e3^2 - e1^2)/(2*e2*e3));
  a2 := acos((e1^2 + e3^2 - e2^2)/(2*e1*e3));
  return minimum(minimum(a1, a2), pi - a1 - a2)*180/pi
}
calc_minangle := {
  minangle := min(facet ff, cornermin(ff.edge[1].length, ff.edge[2].length, ff.edge[3].length))
}
perturb := {
  set vertex x x + 0.001*sin(12.9898*id);
  set vertex y y + 0.001*sin(78.233*id);
  set vertex z z + 0.001*sin(37.719*id);
  recalc
}
procedure recipe(integer rounds, integer gsteps) {
  local kk;
  calc_minangle;
  printf "round 0 vertices %d W %.15g minangle %.6g clock %.3f\n", vertex_count,
    willmore.value, minangle, clock;
  quietgo on;
  for ( kk := 1 ; kk <= rounds ; kk++ ) {
    g gsteps; V; u; n 1.0; g gsteps;
    calc_minangle;
    printf "round %d vertices %d W %.15g minangle %.6g clock %.3f\n", kk, vertex_count,
      willmore.value, minangle, clock
  };
  quietgo off
}
perturb
recipe(50, 20) // default run
