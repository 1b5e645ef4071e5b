"""A first scene: a circular opening excavated in a granite block under in-situ stress, stepped by YADE.

    yade -n -x examples/first_scene.py            # or: /usr/bin/python3 examples/first_scene.py [steps]

The block carries the in-situ stress (σxx, σyy) = (−20, −10) MPa (tension positive) and the same far-field
traction on its faces, so only the opening's wall is out of balance; damped steps bring it to the
Kirsch state. Writes out/first_scene/particles.vtu (ParaView) and prints the hoop stress at the wall.
"""
import sys

import numpy as np
import yade_mpm as ym
from yade import O
from yade.wrapper import ForceResetter, NewtonIntegrator

steps = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
lo, hi, centre, radius = (0.0, 0.0), (3.0, 3.0), (1.5, 1.5), 0.25                      # [m]
s = ym.make_solver(lo, hi, spacing=0.05)                       # grid over the block (+2 cells margin)
rock = ym.rocks.granite()                                      # paper Sec. 3.1: E = 22.41 GPa, ν = 0.2313
ym.add_region(s, rock, lo, hi, ppc=2, holes=[ym.Circle(centre, radius)])
sxx, syy = -20e6, -10e6                                        # in-situ stress, tension positive [Pa]
ym.set_initial_stress(s, (sxx, syy, rock.poisson * (sxx + syy), 0.0))   # plane strain σzz
for axis, far in ((0, sxx), (1, syy)):                         # far-field traction σ0·n on the four faces
    for side, face in ((-1, lo[axis]), (1, hi[axis])):
        ym.apply_face_traction(s, axis, side, face, tuple(side * far if a == axis else 0.0 for a in range(2)))
s.damping = 0.3                                                # Cundall local damping (quasi-static)
O.engines = [ForceResetter(), ym.MpmEngine(s, label="mpm").runner(), NewtonIntegrator()]
O.dt = 1.0                                                     # lowered to the MPM stable step
O.run(steps, True)

pos, stress = ym.get(s, "pos"), ym.get(s, "stress")            # row k = particle id k; stress: xx, yy, zz, xy [Pa]
top = np.argmin(np.hypot(pos[:, 0] - centre[0], pos[:, 1] - centre[1] - radius))    # the particle nearest the crown
print(f"t = {O.time * 1e3:.3f} ms after {O.iter} steps; crown hoop stress σxx = {stress[top, 0] / 1e6:.1f} MPa "
      f"(Kirsch at the wall: {(3 * sxx - syy) / 1e6:.0f} MPa)")
ym.output.write_particles("out/first_scene/particles", s)
