// command-language features of issue 6, run on cube.fe by both programs
procedure pp(real aa, integer bb)
{ printf "pp %g %g\n", aa, bb }
pp(1.5, 2.7)
function real twice_plus(real xx) { local yy; yy := xx*2; return yy+1 }
print twice_plus(3)
xx := 5
print twice_plus(xx)
print xx
procedure countdown(integer nn) {
  if nn <= 0 then return; printf "%d\n", nn; countdown(nn-1) }
countdown(3)
function real fact(real nn) { if nn <= 1 then return 1; return nn*fact(nn-1) }
print fact(10)
for (ii := 1; ii < 10; ii++) {
  if ii == 3 then continue; if ii == 6 then break; printf "%d ", ii };
printf "\n"
kk := 0; do { kk += 2 } while kk < 7; print kk
jj := 0; while 1 do { jj++; if jj >= 4 then break }; print jj
for (ii := 1; ii <= 3; ii += 1) {
  for (mm := 1; mm <= 3; mm += 1) { if mm == 2 then break; printf "%d%d ", ii, mm } };
printf "\n"
{ printf "rep\n" } 3
print (xx > 2) ? 10 : 20
define vertex attribute onum integer
set vertex onum 2.7
print vertex[1].onum
vertex[2].onum := -3.9
print vertex[2].onum
set vertex[3] onum onum+5
print vertex[3].onum
define facet attribute fvec real[3]
set facet fvec[2] area*4
print sum(facet, fvec[2])
fix vertex where z > 0.5
unfix vertex[5]
fix edge where id < 4
print sum(vertex, fixed)
unfix vertices
histogram(edge, length)
loghistogram(facet, area)
histogram(vertex where id < 0, x)
define arr real[3]
arr[2] := 7
arr[3] += 1.5
print arr[2]+arr[3]
print arr
define mat real[2][2]
mat := {{1, 2}, {3, 4}}
print mat[2][1]
print sizeof("abcd")
print is_defined("twice_plus")
print is_defined("nosuchname")
label := sprintf "%05.1f|%s", 3.14159, "ab"
print label
foreach vertex[1].edge ee do printf "%d ", ee.oid; printf "\n"
foreach edge[1].facet ff do printf "%d ", ff.oid; printf "\n"
print facet[2].edge[1].length
print edge[5].vertex[2].id
print facet[1].color
set facet[1] color red
print facet[1].backcolor
print sum(edge, show)
print sum(facet, show)
print vertex[1].vertex_normal[1]
print vertex[2].x[2]
print view_matrix[1][4]
print linear
print rgb_colors
vv := 0
foreach facet ff where ff.color == white and ff.id < 24 do {
  set facet[ff.id+1] color green; vv += 1 }
print vv
gogo_letter := 0
r :::= { gogo_letter += 1 }
r
r
print gogo_letter
print vertex_count
'r'
print vertex_count
