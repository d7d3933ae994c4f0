// Language features checked against evolver-nox-d (tests/commands/test_language.py)
// history and its recall
print 1
aa := 5
print aa+1
!!
!pr
history
// quiet: counts, v, list headers and toggle messages suppressed
quiet on
r
v
list vertex[1]
conj_grad on
quiet off
conj_grad off
quietgo on
quietgo off
autorecalc off
autorecalc on
check_increase on
check_increase off
// fix/unfix and refine counts reported once per command, at its end
fx := { unfix vertices; fix vertex where id < 4; print 5; refine edge[1]; refine edge[2] }
fx
// run-time constraints by name
define constraint cc formula: x^2 + y^2 = 4
set vertex[1] constraint cc
list vertex[1]
print vertex[1].on_constraint cc
print vertex[1].on_constraint 2
print sum(vertex, on_constraint cc)
define constraint dd formula: z = 0.5
set vertex[5] constraint dd
list vertex[5]
unset vertex[5] constraint dd
list vertex[5]
// defined attributes in list
define vertex attribute va real
define vertex attribute vb integer[2]
define edge attribute ea real[3]
define facet attribute fa integer
define body attribute ba real
set vertex va id/3
set vertex[2] vb[2] 7
set edge[1] ea[3] 2.5
set facet[1] fa 4
list vertex[2]
list edge[1]
list facet[1]
list body[1]
// whole arrays
define vn real[3]
vn := vertex[7].vertex_normal
print vn
vn := 2*vn
print vn*vn
define mm real[2][3]
mm[1] := vertex[2].__x
mm[2] := edge[1].edge_vector
mm[2] += {1,2,3}
print mm
vn /= sqrt(vn*vn)
print vn
foreach edge ee where id < 4 do print ee.edge_vector[2]
// a single = compares; a lone printf format is printed as it is
print 3 = 1
if 2 = 2 then print 5 else print 6
printf "%%x\n"
printf "a%%b %d\n", 3
// elliptic integrals
print ellipticK(0.5)
print ellipticE(0.5)
print incompleteEllipticF(1.2, 0.7)
print incompleteEllipticF(4.0, 0.3)
print incompleteEllipticE(-4.0, 0.3)
// names side by side, set gen.attr, valid_element, frontbody
print sum(vertex[1].edge eee, eee length)
define edge attribute eb real
set facet[2].edges.eb 3 where id > 10
print sum(edge, eb)
print valid_element(vertex[3]) + valid_element(vertex[999])
foreach facet ff where id < 4 do printf "%d %d\n", ff.frontbody, ff.backbody
