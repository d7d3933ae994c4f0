// Figure 3 (pyevolver only): continuation in the regularization weight.
// Minimizes W + lambda*E (E = harmonic_energy, the area fixed) with `newton`
// for lambda = lam0, lam0*f, lam0*f^2, ... while the mesh stays healthy:
//
//     pyevolver torus10x16_offset_normal_harmonic.fe -f fig3_continuation.cmd
//
// healthy: the smallest facet angle is at least minangle_ok (10 degrees).
//   A stage that ends unhealthy is undone (the coordinates of the last healthy
//   stage are restored) and lambda is lowered by a smaller factor (f -> sqrt f)
//   until f > 0.97.
// Loop guide: loop_w is the Willmore energy of the smooth Loop subdivision
//   surface of the mesh (the quantity loop_w), an energy of a genuine smooth
//   torus, so never below 2 pi^2.  The stage with the lowest loop_w is kept;
//   the run stops after maxrises stages in a row without a new lowest loop_w
//   (and at lambda < lammin), and ends on that best stage.
// One line per stage: stage, lambda, W (the quantity willmore), smallest angle,
// loop_w, clock, healthy/undone; then "result ..." for the stage kept.
// To change the schedule run  continuation(lam0, f, lammin, steps, maxrises).
//
// consistency(lam0, f, lammin, steps, nbis): the other rule for lambda, an
//   a-posteriori consistency test.  W and loop_w estimate the same Willmore
//   energy; while lambda's bias dominates W > loop_w, once the PL energy
//   starts to cheat W < loop_w.  Lower lambda by f while the mesh is healthy
//   and W > loop_w; the first stage with W <= loop_w (or unhealthy) brackets
//   the crossing, which nbis bisections in log(lambda) (each from the last
//   healthy W > loop_w stage) narrow down; the healthy stage with the smallest
//   |W - loop_w| is kept.  Stage lines end in healthy (W > loop_w), crossed
//   (healthy, W <= loop_w) or undone (unhealthy).
//   To run it, replace the last line (the default run) by
//     consistency(0.25, 0.7, 0.001, 100, 8)

minangle_ok := 10
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
define vertex attribute healthy_x real[3]
define vertex attribute best_x real[3]
keep_healthy := { set vertex healthy_x[1] x; set vertex healthy_x[2] y; set vertex healthy_x[3] z }
back_to_healthy := { set vertex x healthy_x[1]; set vertex y healthy_x[2]; set vertex z healthy_x[3]; recalc }
keep_best := { set vertex best_x[1] x; set vertex best_x[2] y; set vertex best_x[3] z }
back_to_best := { set vertex x best_x[1]; set vertex y best_x[2]; set vertex z best_x[3]; recalc }

// newton in batches of 10 steps, stopped early when the mesh turns unhealthy
// (a collapsing stage is undone anyway) or the energy no longer changes
procedure stage_newton(integer steps) {
  local kk, e0, done;
  kk := 0; done := 0;
  while done == 0 do {
    e0 := total_energy;
    newton 10;
    kk := kk + 10;
    calc_minangle;
    if minangle < minangle_ok or kk >= steps or abs(total_energy - e0) <= 1e-12*abs(e0)
      then done := 1
  }
}

procedure continuation(real lam0, real fac0, real lammin, integer steps, integer maxrises) {
  local lam, fac, stage, bestloop, bestlam, rises, done;
  perturb;
  keep_healthy;
  lam := lam0; fac := fac0; stage := 0; bestloop := 1e30; bestlam := lam0; rises := 0;
  done := 0;
  while done == 0 do {
    harmonic.modulus := lam;
    stage_newton(steps);
    stage := stage + 1;
    if minangle >= minangle_ok then {
      printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f healthy\n",
        stage, lam, willmore.value, minangle, loop_w.value, clock;
      keep_healthy;
      if loop_w.value < bestloop then {
        bestloop := loop_w.value; bestlam := lam; rises := 0; keep_best
      } else rises := rises + 1;
      if rises >= maxrises or lam*fac < lammin then done := 1 else lam := lam*fac
    } else {
      printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f undone\n",
        stage, lam, willmore.value, minangle, loop_w.value, clock;
      back_to_healthy;
      lam := lam/fac;
      fac := sqrt(fac);
      if fac > 0.97 then done := 1 else lam := lam*fac
    }
  };
  back_to_best;
  harmonic.modulus := bestlam;
  calc_minangle;
  printf "result lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f\n", bestlam,
    willmore.value, minangle, loop_w.value, clock
}
procedure consistency(real lam0, real fac, real lammin, integer steps, integer nbis) {
  local lam, lhi, llo, dd, bestd, bestlam, stage, done, kk;
  perturb;
  keep_healthy;
  keep_best;                  // the start, should the first stage be undone
  lam := lam0; lhi := 0; llo := 0; bestd := 1e30; bestlam := lam0; stage := 0; done := 0;
  while done == 0 do {
    harmonic.modulus := lam;
    stage_newton(steps);
    stage := stage + 1;
    dd := willmore.value - loop_w.value;
    if minangle >= minangle_ok and dd > 0 then {
      printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f healthy\n",
        stage, lam, willmore.value, minangle, loop_w.value, clock;
      keep_healthy;
      lhi := lam;
      if dd < bestd then { bestd := dd; bestlam := lam; keep_best };
      if lam*fac < lammin then done := 1 else lam := lam*fac
    } else {
      if minangle >= minangle_ok then {
        printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f crossed\n",
          stage, lam, willmore.value, minangle, loop_w.value, clock;
        if abs(dd) < bestd then { bestd := abs(dd); bestlam := lam; keep_best }
      } else
        printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f undone\n",
          stage, lam, willmore.value, minangle, loop_w.value, clock;
      llo := lam;
      done := 1
    }
  };
  if lhi > 0 and llo > 0 then {
    for ( kk := 1 ; kk <= nbis ; kk++ ) {
      lam := sqrt(lhi*llo);
      back_to_healthy;
      harmonic.modulus := lam;
      stage_newton(steps);
      stage := stage + 1;
      dd := willmore.value - loop_w.value;
      if minangle >= minangle_ok then {
        if dd > 0 then
          printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f healthy\n",
            stage, lam, willmore.value, minangle, loop_w.value, clock
        else
          printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f crossed\n",
            stage, lam, willmore.value, minangle, loop_w.value, clock;
        if abs(dd) < bestd then { bestd := abs(dd); bestlam := lam; keep_best }
      } else
        printf "stage %d lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f undone\n",
          stage, lam, willmore.value, minangle, loop_w.value, clock;
      if minangle >= minangle_ok and dd > 0 then { lhi := lam; keep_healthy } else llo := lam
    }
  };
  back_to_best;
  harmonic.modulus := bestlam;
  calc_minangle;
  printf "result lambda %.10g W %.15g minangle %.6g loop_w %.15g clock %.3f\n", bestlam,
    willmore.value, minangle, loop_w.value, clock
}
continuation(0.25, 0.7, 0.001, 100, 2) // default run
