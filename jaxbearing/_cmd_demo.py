"""`jaxbearing demo`: summary of the embedded reference bearing."""

from __future__ import annotations


def register(sub) -> None:
    p = sub.add_parser("demo", help="summarise the embedded reference bearing (and run it)")
    p.set_defaults(func=run)


def summary_lines(bearing, op) -> list[str]:
    from ._params import kinematic_cage_speed, rad_s_to_rpm

    r = bearing.roller
    i_ax, i_tr = (float(v) for v in bearing.roller_inertia)
    c_p, c_t = (float(v) for v in bearing.cage_inertia)
    return [
        "Reference bearing (representative aero-engine mainshaft bearing, not the paper's Table 1)",
        f"  pitch diameter            {float(bearing.pitch_diameter) * 1e3:9.3f} mm",
        f"  rollers                   {bearing.num_rollers} x D {float(r.diameter) * 1e3:.3f} mm"
        f" x L {float(r.length) * 1e3:.3f} mm, R_end {float(r.end_radius) * 1e3:.1f} mm",
        f"  roller mass               {float(bearing.roller_mass) * 1e3:9.4f} g",
        f"  roller inertia axial      {i_ax:9.4e} kg m^2",
        f"  roller inertia transverse {i_tr:9.4e} kg m^2",
        f"  cage mass                 {float(bearing.cage_mass) * 1e3:9.3f} g",
        f"  cage inertia polar        {c_p:9.4e} kg m^2",
        f"  cage inertia transverse   {c_t:9.4e} kg m^2",
        f"  inner ring speed          {float(rad_s_to_rpm(op.inner_speed)):9.1f} rpm",
        f"  radial load               {float(op.radial_load):9.1f} N",
        f"  kinematic cage speed      {float(rad_s_to_rpm(kinematic_cage_speed(bearing, op))):9.1f} rpm",
    ]


def run(args) -> int:
    from ._params import reference_bearing, reference_operating_point

    print("\n".join(summary_lines(reference_bearing(), reference_operating_point())))
    return 0
