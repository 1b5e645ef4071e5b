"""The rigid YADE bodies and engines of the loading scenes (2D: 1 m thick boxes, the unit slice of
plane strain): a platen pushed at constant speed, a free filler of a flaw, the engine list."""
import math

PLATEN_SPEED = 0.1                 # downward velocity of the rigid top platen [m/s] (paper Secs. 3.3, 4)
PLATEN_FRICTION = 0.0              # platen–rock μ_con [-]: the paper's free-slip top
FILLER_CHI = 0.5                   # filler–rock residual penetration factor χ [-] (doc/validation/tunnel.md, doc/reference/contact.md)
BODY_HALF_THICKNESS = 0.5          # YADE box half-extent along z [m]: thickness 1 m


def yade_platen(rb, x_center, top, width, spacing, speed, friction, cohesion=0.0, d0=None, law=None):
    """A rigid YADE Box platen resting on the specimen top y = `top` [m] (its lower face there: the top
    particle row is then at the default detection distance, half a particle edge), 1.2 × `width` wide
    and 10 cells high, blockedDOFs 'xyzXYZ', moving down at `speed` [m/s]; registered in the
    RigidBodies `rb` with μ = friction [-], c = cohesion [Pa], detection distance d0 (None: half the
    particle edge, ``RigidBodies.add``) and contact law `law` (None: the declared default). Returns its YADE id."""
    from yade import O, utils
    hp = 5 * spacing                               # platen half-height
    pid = O.bodies.append(utils.box((x_center, top + hp, 0), (0.6 * width, hp, BODY_HALF_THICKNESS), fixed=False))
    O.bodies[pid].state.blockedDOFs = "xyzXYZ"
    O.bodies[pid].state.vel = (0, -speed, 0)
    rb.add(pid, mu=friction, cohesion=cohesion, d0=d0, law=law)
    return pid


def blocked_dofs(value, name="blockedDOFs"):
    """A YADE blockedDOFs string: letters of 'xyzXYZ' (x, y, z translation; X, Y, Z rotation), each at
    most once ('' = free); ValueError naming `name` otherwise (YADE ignores unknown letters silently)."""
    if not isinstance(value, str) or any(c not in "xyzXYZ" for c in value) or len(set(value)) != len(value):
        raise ValueError(f"{name} = {value!r} must be letters of 'xyzXYZ' (x, y, z translation, X, Y, Z rotation), each at most "
                         "once, e.g. 'zXY' (free in the x–y plane) or 'zXYZ' (no rotation)")
    return value


def yade_filler(rb, flaw, friction, cohesion=0.0, density=None, blocked="zXY", chi=None, law=None):
    """A free rigid YADE Box that is the flaw (dict of ``tunnel_flaw``): the domain of the filling, its
    length × width, registered in `rb` with d0 = "initial" (doc/reference/contact.md) so the particles next to it —
    the flaw is cut from the particle lattice, its faces are jagged — touch it at zero force from t = 0;
    free in the plane (blockedDOFs `blocked`, default 'zXY'; 'zXYZ' also blocks its rotation); μ = friction
    [-], c = cohesion [Pa], χ = chi [-] (None: FILLER_CHI); density [kg/m³] (None: YADE's default 1000):
    its true mass, lighter than the grid nodes along its faces — the stick step moves it with its contact
    nodes (doc/reference/contact.md). The grid nodes it covers get the contact exclusion bit, as an open flaw's nodes
    get the user bit. law: contact law (None: the declared default). Returns its YADE id."""
    from yade import O, utils
    from yade.minieigenHP import Quaternion, Vector3
    from yade.wrapper import FrictMat
    blocked = blocked_dofs(blocked, "blocked")
    ang = math.atan2(flaw["direction"][1], flaw["direction"][0])
    kw = {} if density is None else dict(material=FrictMat(density=density))
    fid = O.bodies.append(utils.box((flaw["center"][0], flaw["center"][1], 0), (0.5 * flaw["length"], 0.5 * flaw["width"], BODY_HALF_THICKNESS),
                                    orientation=Quaternion(Vector3(0, 0, 1), ang), fixed=False, **kw))
    st = O.bodies[fid].state
    st.blockedDOFs = blocked                       # default in the plane: x, y, rotation about z
    rb.add(fid, mu=friction, cohesion=cohesion, chi=FILLER_CHI if chi is None else chi, d0="initial", law=law)
    return fid


def yade_engines(solver, rb, label):
    """O.engines = [ForceResetter, the MpmEngine (with the RigidBodies `rb`, or None), NewtonIntegrator
    (no damping, no gravity)]; O.dt is lowered to the MPM stable step by the engine. Returns the MpmEngine."""
    from yade import O
    from yade.wrapper import ForceResetter, NewtonIntegrator
    from yade_mpm.engine import MpmEngine
    eng = MpmEngine(solver, label=label, bodies=rb)
    O.engines = [ForceResetter(), eng.runner(), NewtonIntegrator(damping=0.0, gravity=(0, 0, 0))]
    O.dt = 1.0
    return eng
