"""Cage guided on the outer-ring lands: short journal bearing, rub contact, viscous torque.

Film viscosity: the lands run in the oil-air mixture of the bearing cavity, so the film has the
mixture's viscosity eta = f_oil eta_0 (`_drag.mixture_viscosity`), not that of a flooded film.
(With eta_0 itself the Petroff torque at the reference point is about 0.9 N m, ten times the
cage's churning torque and more than the rollers can drive: the cage decelerates without bound
over the first tens of milliseconds. This is a modelling assumption; a flooded-land bearing
would set oil_fraction = 1 for the lands, which the configuration does not yet separate.)

The cage's outer cylinder (radius R = D_co/2) runs inside the two guiding lands of the outer
ring (width b_l each, radial clearance c = C_g/2), like a journal in a stationary sleeve. The
outer ring is fixed at the origin; the cage centre c_c = (0, y_c, z_c) gives the eccentricity
vector e (its YZ part) and the eccentricity ratio eps = |e|/c. With n = e/|e| and
t = X x n (the direction a positive rotation about +X moves the point of the cage at n):

Hydrodynamic force (Ocvirk short-bearing, pi-film/Guembel cavitation, one land of width L):
the short-bearing Reynolds equation d/dz(h^3 dp/dz) = 6 eta (omega - 2 phi') dh/dtheta
+ 12 eta dh/dt (theta measured from n towards t, dh/dt at fixed theta: the squeeze) with
h = c (1 - eps cos theta), integrated over the half film theta in (pi, 2 pi), gives
(eps' = d eps/dt, phi' = whirl rate of the line of centres)

    F_n = -(eta R L^3 / c^2) [ eps^2 (omega - 2 phi') / (1 - eps^2)^2
                              + pi (1 + 2 eps^2) eps' / (2 (1 - eps^2)^(5/2)) ]
    F_t =  (eta R L^3 / c^2) [ pi eps (omega - 2 phi') / (4 (1 - eps^2)^(3/2))
                              + 2 eps eps' / (1 - eps^2)^2 ]

(Hamrock, Schmid & Jacobson, "Fundamentals of Fluid Film Lubrication", 2nd ed., the
short-width journal bearing, for the steady terms W_r = eta omega R L^3 eps^2 / (c^2
(1 - eps^2)^2), W_t = pi eta omega R L^3 eps / (4 c^2 (1 - eps^2)^(3/2)); the squeeze and
whirl terms as in Childs, "Turbomachinery Rotordynamics", 1993, short-bearing model, and
San Andres' notes on squeeze-film dampers). The wedge uses the effective speed
omega_c - 2 phi' (the ring is fixed); the pressurised half is kept at theta in (pi, 2 pi), the
converging half of steady rotation (the usual superposition of wedge and squeeze terms).
Whirl and squeeze enter through eps phi' = (v/c) . t and eps' = (v/c) . n,
so nothing divides by |e|. Using n n^T + t t^T = I in the YZ plane, the squeeze part becomes

    -(eta R L^3 / c^2) (pi/2) [ v/c / (1 - eps^2)^(3/2) + 3 eps^2 ((v/c).n) n / (1 - eps^2)^(5/2) ]

which is smooth at e = 0, where the film force is the isotropic squeeze damping
-(pi eta R L^3 / (2 c^3)) v. The remaining terms vanish like eps; they are continuous but only
Lipschitz at e = 0 (the direction n is undefined there), where `safe_norm` gives finite
gradients. Both lands act in parallel: twice the one-land force with L = b_l.

Capped eccentricity. The Ocvirk formulas diverge at eps = 1, and the cage may reach or pass
the clearance (then the rub contact below carries it). The film therefore sees

    eps_f = eps                                                    for eps <= eps_1,
    eps_f = eps_1 + (eps_max - eps_1) tanh((eps - eps_1)/(eps_max - eps_1))  above,

(default eps_1 = 0.8, eps_max = 0.95): exact Ocvirk below eps_1, C2 at eps_1, bounded by eps_max
so the film force stays finite for any eps (also eps >= 1 during diffrax step rejection).

Rub contact when the clearance is used up (delta = |e| - c > 0): a stiff line contact of the
cage cylinder on both lands, Q = k_c softplus_w(delta)^(10/9) with
k_c = `contact.line_contact_stiffness`(2 b_l, E'(cage, ring)) (ISO/TS 16281 line contact over
the total land width; the conformal contact is stiffer than this, so the law is a conservative
penalty that keeps the cage in its clearance), Hunt-Crossley damping on the approach rate v . n
(as in `_raceway`), and Coulomb friction mu_p = `Bearing.pocket_friction` (steel cage on the
steel land, lubricated) opposing the sliding speed u = v . t + omega_c R of the cage surface at
the contact, direction smoothed by SLIDING_EPS.

Viscous drag torque on the cage (Petroff's equation, Couette shear of the full film on both
lands; Hamrock, Schmid & Jacobson; Harris & Kotzalas, "Advanced Concepts", cage-land friction):

    M_x = -2 pi eta R^3 (2 b_l) omega_c / (c sqrt(1 - eps_f^2))

(the Poiseuille contribution of the pressure field, a torque of order eps c F_t / 2, is
neglected), plus the rub friction torque R F_friction. eta is the mixture viscosity f_oil eta_0
(see the top of this docstring).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, ArrayLike, Float

from ..contact import (
    HUNT_CROSSLEY_ALPHA,
    PENETRATION_WIDTH,
    SLIDING_EPS,
    effective_modulus,
    hertz_force,
    hunt_crossley_factor,
    line_contact_stiffness,
    safe_norm,
)
from ..geometry import Bearing
from ._drag import mixture_viscosity

#: eps_1: below this eccentricity ratio the film force is exactly Ocvirk's.
FILM_ECCENTRICITY_KNEE = 0.8
#: eps_max: the capped eccentricity ratio seen by the film never exceeds this.
FILM_ECCENTRICITY_MAX = 0.95
#: Line-contact exponent of the rub contact (Palmgren, ISO/TS 16281).
_LINE_EXPONENT = 10.0 / 9.0

_X = np.array([1.0, 0.0, 0.0])
_YZ = np.array([0.0, 1.0, 1.0])


def capped_eccentricity(
    eps: ArrayLike,
    knee: float = FILM_ECCENTRICITY_KNEE,
    maximum: float = FILM_ECCENTRICITY_MAX,
) -> Array:
    """eps_f: identity up to `knee`, then knee + (max - knee) tanh((eps - knee)/(max - knee)).

    C2 at the knee (tanh'(0) = 1, tanh''(0) = 0), strictly increasing, bounded by `maximum`.
    """
    eps = jnp.asarray(eps)
    span = maximum - knee
    above = knee + span * jnp.tanh((eps - knee) / span)
    return jnp.where(eps <= knee, eps, above)


def land_contact_stiffness(bearing: Bearing) -> Float[Array, ""]:
    """k_c of the cage-on-land rub contact [N/m^(10/9)]: ISO/TS 16281 line contact over the total
    land width 2 b_l with E'(cage, ring)."""
    e_prime = effective_modulus(
        bearing.cage_material.elastic_modulus,
        bearing.cage_material.poisson_ratio,
        bearing.ring_material.elastic_modulus,
        bearing.ring_material.poisson_ratio,
    )
    return line_contact_stiffness(2 * bearing.cage.land_width, e_prime)


def cage_land_forces(
    bearing: Bearing,
    cage_centre: Float[Array, 3],
    cage_velocity: Float[Array, 3],
    cage_speed: Float[Array, ""],
    *,
    damping: ArrayLike = HUNT_CROSSLEY_ALPHA,
    penetration_width: float = PENETRATION_WIDTH,
    speed_eps: float = SLIDING_EPS,
    eccentricity_knee: float = FILM_ECCENTRICITY_KNEE,
    eccentricity_max: float = FILM_ECCENTRICITY_MAX,
) -> tuple[Float[Array, 3], Float[Array, ""]]:
    """(force on the cage (3,), torque on the cage about X) from both outer-ring lands.

    Ocvirk film force with squeeze and whirl, rub contact beyond the clearance, Petroff torque
    and rub friction (module docstring). Axial (X) components of position and velocity are
    ignored; the returned force has no X component.
    """
    eta = mixture_viscosity(bearing)  # the lands run in the cavity's oil-air mixture
    radius = bearing.cage.outer_diameter / 2
    clearance = bearing.cage.guiding_clearance / 2
    land = bearing.cage.land_width
    omega = jnp.asarray(cage_speed)

    ecc = jnp.asarray(cage_centre) * _YZ
    vel = jnp.asarray(cage_velocity) * _YZ
    e_len = safe_norm(ecc)
    ok = e_len > 0
    n = jnp.where(ok, ecc / jnp.where(ok, e_len, 1.0), 0.0)
    t = jnp.cross(_X, n)
    eps = e_len / clearance
    eps_f = capped_eccentricity(eps, eccentricity_knee, eccentricity_max)
    s = 1.0 - eps_f**2

    vd = vel / clearance  # (v / c): eps' = vd . n, eps phi' = vd . t
    vn = jnp.dot(vd, n)
    vt = jnp.dot(vd, t)
    scale = 2 * eta * radius * land**3 / clearance**2  # two lands in parallel
    f_n = -(eps_f**2 * omega - 2 * eps_f * vt) / s**2 - 1.5 * jnp.pi * eps_f**2 * vn / s**2.5
    f_t = jnp.pi * eps_f * omega / (4 * s**1.5) + 2 * eps_f * vn / s**2
    film = scale * (f_n * n + f_t * t - 0.5 * jnp.pi * vd / s**1.5)

    # rub contact on the lands
    v_n = jnp.dot(vel, n)
    q_el = hertz_force(e_len - clearance, land_contact_stiffness(bearing), penetration_width, _LINE_EXPONENT)
    factor = hunt_crossley_factor(v_n, damping)
    q = q_el * factor
    slide = jnp.dot(vel, t) + omega * radius
    friction = -bearing.pocket_friction * q * slide / jnp.sqrt(slide**2 + speed_eps**2)
    rub = -q * n + friction * t

    petroff = -2 * jnp.pi * eta * radius**3 * (2 * land) * omega / (clearance * jnp.sqrt(s))
    torque = petroff + radius * friction
    return film + rub, torque
