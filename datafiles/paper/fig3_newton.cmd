// Figure 3 (pyevolver only): minimize the energy of a torus*_*.fe datafile
// with damped Newton steps (the `newton` command: exact Hessian, all three
// directions per vertex, Levenberg-Marquardt damping; the area stays fixed).
//
//     pyevolver torus10x16_offset_normal_harmonic.fe -f fig3_newton.cmd
//
// On a *_harmonic.fe file the regularization weight lambda is the modulus of
// the quantity harmonic: set it first, e.g.  harmonic.modulus := 0.1
// The vertices are first moved by about 1e-3 by a fixed formula (the exact
// grid is a symmetric critical point).  Prints one line "result ...":
// vertices, W (the quantity willmore), smallest facet angle in degrees,
// clock (seconds since pyevolver started).

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
procedure minimize(integer steps) {
  perturb;
  newton steps;
  calc_minangle;
  printf "result vertices %d W %.15g minangle %.6g clock %.3f\n", vertex_count,
    willmore.value, minangle, clock
}
minimize(300) // default run
