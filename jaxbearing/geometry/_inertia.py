"""Masses and inertias derived from geometry and density.

Roller: a body of revolution whose half-length at radius rho from its axis is x(rho) (cylinder,
corner torus, arc end cap; the few-micrometre crown is neglected). With shells of radius rho:

    m      = rho_m int_0^{D/2} 2 pi rho 2 x(rho) drho
    I_ax   = rho_m int 2 pi rho^3 2 x(rho) drho
    I_tr   = rho_m int 2 pi rho (rho^2 x(rho) + 2 x(rho)^3 / 3) drho    (about a diameter)

evaluated by Gauss-Legendre quadrature on [0, rho_lim] (end face) and, with
rho = R_ce + R_cor sin(phi), on the torus (smooth in phi). Exact for a cylinder.

Cage: annulus (D_o, D_i, width W) less Z pockets of (D + C_p) x (L_b1 + C_p) through the wall;
the pockets' material is taken at the same radial distribution as the annulus.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

if TYPE_CHECKING:  # annotations only (Bearing's mass properties call this module)
    from ._params import Bearing, Roller
from ._roller_end import arc_half_length, limited_circle_radius

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(32)


def roller_mass_properties(roller: Roller, density) -> tuple[Array, Array, Array]:
    """(mass, axial inertia, transverse inertia about the centre) of one roller."""
    rho_lim = limited_circle_radius(roller)
    r_ce = roller.corner_centre_radius
    r_cor = roller.corner_radius
    x_cor = roller.corner_centre_offset

    def shells(rho, x, jac):
        # integrands of m, I_ax, I_tr per unit rho (times the Jacobian jac)
        w = 2 * jnp.pi * rho * jac
        return jnp.stack([w * 2 * x, w * rho**2 * 2 * x, w * (rho**2 * x + 2 * x**3 / 3)])

    def face(rho):
        return shells(rho, arc_half_length(roller, rho), 1.0)

    def torus(phi):
        rho = r_ce + r_cor * jnp.sin(phi)
        return shells(rho, x_cor + r_cor * jnp.cos(phi), r_cor * jnp.cos(phi))

    phi_lim = jnp.arcsin((rho_lim - r_ce) / r_cor)
    x_face = 0.5 * rho_lim * _GL_NODES + 0.5 * rho_lim
    x_tor = 0.5 * (jnp.pi / 2 - phi_lim) * _GL_NODES + 0.5 * (jnp.pi / 2 + phi_lim)
    total = 0.5 * rho_lim * (face(x_face) @ _GL_WEIGHTS) + 0.5 * (jnp.pi / 2 - phi_lim) * (
        torus(x_tor) @ _GL_WEIGHTS
    )
    m, i_ax, i_tr = density * total
    return m, i_ax, i_tr


def cage_mass_properties(bearing: Bearing) -> tuple[Array, Array, Array]:
    """(mass, polar inertia, transverse inertia about the centre) of the cage."""
    c = bearing.cage
    rho = bearing.cage_material.density
    do2, di2 = c.outer_diameter**2, c.inner_diameter**2
    m_annulus = rho * jnp.pi / 4 * (do2 - di2) * c.width
    pocket_length = bearing.roller.length + c.pocket_clearance
    v_pockets = (
        bearing.num_rollers
        * (bearing.roller.diameter + c.pocket_clearance)
        * pocket_length
        * (c.outer_diameter - c.inner_diameter)
        / 2
    )
    m_pockets = rho * v_pockets
    m = m_annulus - m_pockets
    i_polar = m * (do2 + di2) / 8
    i_trans = m_annulus * ((do2 + di2) / 16 + c.width**2 / 12) - m_pockets * (
        (do2 + di2) / 16 + pocket_length**2 / 12
    )
    return m, i_polar, i_trans


def inner_ring_inertia(bearing: Bearing) -> tuple[Array, Array]:
    """(axial, transverse) inertia of the inner ring about its centre [kg m^2].

    The ring's effective mass m_i (`Bearing.inner_ring_mass`, which includes the shaft) is taken
    as a thin-walled cylinder of radius R_i (the inner raceway radius) and width
    W_r = L_b1 + Delta_bf (the flange spacing):

        I_axial = m_i R_i^2,        I_transverse = m_i (R_i^2 / 2 + W_r^2 / 12)

    (thin cylindrical shell about its axis and about a diameter through its centre; Gere &
    Goodno, Mechanics of Materials, App. E; the limit of the hollow cylinder's
    m (R_1^2 + R_2^2)/4 + m L^2/12 as R_1, R_2 -> R_i). Every real ring and shaft has its
    material at radii <= R_i, so these are upper bounds of the ring's inertia for its mass; they
    enter only the tilt degrees of freedom (off by default).
    """
    m = bearing.inner_ring_mass
    r = bearing.inner_raceway_radius
    w = bearing.raceway_width
    return m * r**2, m * (r**2 / 2 + w**2 / 12)
