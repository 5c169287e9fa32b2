"""Brute-force references of the contact stability tests (tests/dynamics/test_equilibrium_region.py,
test_wrench_balance.py, test_contact_set.py): the defining LPs, written independently of the code under test.

The unknowns are the contact forces f_i themselves (3 each, free), each held in its linearised friction cone by the
cone's faces (the planes through consecutive edges u_j, u_{j+1}: (u_j x u_{j+1}) . f_i >= 0), not by the edge
multipliers of the code's span form; the edges are the code's (snakehead.dynamics.contact_set
.friction_cone_generators), so that both describe the same pyramids.
"""
import numpy as np
from scipy.optimize import linprog

from snakehead.dynamics.contact_set import friction_cone_generators
from snakehead.model.physics import GRAVITY


def cone_faces(contacts):
    """(k, e, 3) inward face normals of each contact's pyramid: u_j x u_{j+1} (edges counter-clockwise about n)."""
    u = friction_cone_generators(contacts)
    return np.cross(u, np.roll(u, -1, axis=1))


def forces_exist(contacts, force, moment):
    """Whether forces f_i in the cones give sum f_i = force (3,) and sum p_i x f_i = moment (3,) (about the world
    origin): one HiGHS LP over the 3k force components."""
    p = contacts.points
    k = len(p)
    faces = cone_faces(contacts)
    A_ub = np.zeros((k * faces.shape[1], 3 * k))
    for i in range(k):
        A_ub[i * faces.shape[1]:(i + 1) * faces.shape[1], 3 * i:3 * i + 3] = -faces[i]
    A_eq = np.zeros((6, 3 * k))
    for i in range(k):
        A_eq[:3, 3 * i:3 * i + 3] = np.eye(3)
        x, y, z = p[i]
        A_eq[3:, 3 * i:3 * i + 3] = [[0, -z, y], [z, 0, -x], [-y, x, 0]]  # p x f as a matrix
    res = linprog(np.zeros(3 * k), A_ub=A_ub, b_ub=np.zeros(len(A_ub)), A_eq=A_eq, b_eq=np.r_[force, moment],
                  bounds=(None, None), method="highs")
    assert res.status in (0, 2), res.message
    return res.status == 0


def statically_balanced(contacts, com_xy, mass=3.2, com_z=0.3):
    """The Bretl-Lall definition: forces in the cones with sum f_i = -m g and sum p_i x f_i = -c x m g."""
    weight = np.array([0.0, 0.0, -mass * GRAVITY])
    c = np.array([com_xy[0], com_xy[1], com_z])
    return forces_exist(contacts, -weight, -np.cross(c, weight))
