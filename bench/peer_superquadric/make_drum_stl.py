#!/usr/bin/env python3
"""ASCII STL of a cylinder lateral surface (drum), axis along y, radius R, y in [-L/2, L/2]."""
import math, sys
R, L, nseg = 0.04, 0.04, 64
out = open(sys.argv[1] if len(sys.argv) > 1 else 'drum.stl', 'w')
out.write('solid drum\n')
def tri(p1, p2, p3):
    # normal pointing inward (towards axis) -- orientation does not matter for LIGGGHTS wall/gran
    ux, uy, uz = [p2[i]-p1[i] for i in range(3)]; vx, vy, vz = [p3[i]-p1[i] for i in range(3)]
    n = (uy*vz-uz*vy, uz*vx-ux*vz, ux*vy-uy*vx); nn = math.sqrt(sum(c*c for c in n))
    out.write(' facet normal %g %g %g\n  outer loop\n' % tuple(c/nn for c in n))
    for p in (p1, p2, p3): out.write('   vertex %.9g %.9g %.9g\n' % p)
    out.write('  endloop\n endfacet\n')
for k in range(nseg):
    a0, a1 = 2*math.pi*k/nseg, 2*math.pi*(k+1)/nseg
    A = (R*math.cos(a0), -L/2, R*math.sin(a0)); B = (R*math.cos(a1), -L/2, R*math.sin(a1))
    C = (R*math.cos(a1),  L/2, R*math.sin(a1)); D = (R*math.cos(a0),  L/2, R*math.sin(a0))
    tri(A, B, C); tri(A, C, D)
out.write('endsolid drum\n')
