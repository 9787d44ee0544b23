"""One PD design for every user (ship_guidance.heading_loop, gains.heading_loop_design)
and one ROS_DOMAIN_ID lease (ship_mission.domain)."""
import numpy as np
import pytest

from ship_mission.domain import DomainLease
from ship_autopilot.gains import ZETA, autopilot_gains, heading_loop_design, nomoto_gains
from ship_guidance.heading_loop import pd_design, pd_gains


def test_pd_design_inverts_pd_gains_and_pd_gains_broadcasts():
    a, b = -0.01, -0.002
    zeta, omega_n = np.array([0.6, 0.8, 1.0]), np.array([0.05, 0.1, 0.2])
    k1, k2 = pd_gains(a, b, omega_n=omega_n, zeta=zeta)
    assert k1.shape == k2.shape == (3,)
    for i in range(3):
        assert pd_design(a, b, k1=k1[i], k2=k2[i]) == pytest.approx((zeta[i], omega_n[i]))
    assert isinstance(pd_gains(a, b, omega_n=0.1, zeta=0.8)[0], float)
    with pytest.raises(TypeError):
        pd_gains(a, b, 0.1, 0.8)   # omega_n and zeta by keyword only
    with pytest.raises(ValueError):
        pd_design(a, b, k1=-1.0, k2=1.0)


def test_heading_loop_design_is_what_the_node_builds():
    table = heading_loop_design('mariner')
    assert table.gains == autopilot_gains('mariner') and table.source == 'gain table'
    nm = nomoto_gains('mariner')
    redesign = heading_loop_design('mariner', 'pd', omega_n=0.1)
    assert (redesign.zeta, redesign.omega_n, redesign.source) == (ZETA, 0.1, 'omega_n, zeta')
    k1, k2 = pd_gains(nm['a'], nm['b'], omega_n=0.1, zeta=ZETA)
    assert redesign.gains == {'k1': k1, 'k2': k2}
    given = heading_loop_design('mariner', 'pd', k1=k1, k2=k2)
    assert given.gains == {'k1': k1, 'k2': k2}
    assert (given.zeta, given.omega_n) == (pytest.approx(ZETA), pytest.approx(0.1))
    fuzzy = heading_loop_design('mariner', 'fuzzy_pid', k1=k1, k2=k2, omega_n=0.1)
    assert fuzzy.source == 'gain table'   # k1, k2, omega_n are PD parameters
    with pytest.raises(ValueError):
        heading_loop_design('mariner', 'pd', k1=k1)


def test_domain_leases_are_exclusive_until_closed():
    with DomainLease() as first:
        second = DomainLease()
        try:
            assert first.domain_id != second.domain_id
        finally:
            second.close()
        refused = []
        third = DomainLease(accept=lambda did: refused.append(did) or len(refused) > 1)
        assert third.domain_id not in (first.domain_id, refused[0])
        third.close()
