"""The user field API (yade_mpm.fields): copies in particle-id order under one vocabulary, both stresses
named — the carried (damaged, Eq. 40) and the undamaged one — and the storage-order views kept apart."""
import numpy as np
import pytest
import yade_mpm as ym
from yade_mpm.fields import FIELDS, id_order
from yade_mpm import rocks


def dpgk_block():
    s = ym.make_solver((0, 0), (0.4, 0.4), 0.1)
    ym.add_region(s, rocks.granite_dpgk(), (0, 0), (0.4, 0.4))
    ym.set_initial_stress(s, (1e6, -2e6, -0.3e6, 0.0))        # xx tension, yy compression [Pa]
    return s


def test_damaged_and_undamaged_stress():
    s = dpgk_block()
    ids = ym.get(s, "id")
    D = np.where(ids % 2 == 0, 0.5, 0.0)                       # half the particles half damaged
    s.view("damage")[:] = D[np.argsort(id_order(s))]        # by storage slot: slot k holds id view("id")[k]
    s.requestSort()
    st, und = ym.get(s, "stress"), ym.get(s, "undamaged_stress")
    assert np.allclose(und, [1e6, -2e6, -0.3e6, 0.0])
    # Eq. 40: the tensile principal stress (here σxx) scaled by 1 − D, compression unchanged
    assert np.allclose(st[:, 0], (1 - D) * 1e6) and np.allclose(st[:, 1:], und[:, 1:])
    assert np.allclose(ym.get(s, "max_principal_stress"), (1 - D) * 1e6)
    assert np.array_equal(ym.get(s, "damage"), D)


def test_id_order_and_fields():
    s = dpgk_block()
    x0 = ym.get(s, "pos")
    s.view("v0")[:] = 1.0
    s.requestSort()
    s.run(5)
    f = ym.fields(s)
    assert set(f) == set(FIELDS) | {"time", "steps"} and f["steps"] == 5
    assert np.array_equal(f["id"], np.arange(s.numParticles))  # row k = particle id k, whatever the storage order
    assert np.mean(f["pos"][:, 0] - x0[:, 0]) == pytest.approx(s.time * 1.0, rel=1e-6)   # momentum: equal masses at 1 m/s
    o = id_order(s)
    assert np.array_equal(f["mass"], s.view("mass")[o]) and np.array_equal(f["undamaged_stress"][:, 1], s.view("sig1")[o])


def test_old_and_core_names_point_to_the_user_names():
    s = dpgk_block()
    for old, new in (("state_stress", "undamaged_stress"), ("epsP", "plastic_strain"), ("x", "pos"), ("vol", "volume")):
        with pytest.raises(ValueError, match=new):
            ym.get(s, old)
    with pytest.raises(ValueError, match="fields: id, pos"):
        ym.get(s, "nonsense")
    el = ym.make_solver((0, 0), (0.2, 0.2), 0.1)
    ym.add_region(el, ym.ElasticMat(young=1e9, poisson=0.2, density=2500), (0, 0), (0.2, 0.2))
    assert "cohesion" not in ym.fields(el) and not ym.get(el, "damage").any()
