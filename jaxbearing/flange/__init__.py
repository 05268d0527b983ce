"""Roller end against ring flange (MODEL.md 4.1): contact geometry, kinematics, Hertz force, PV.

- `roller_flange_contact`: one roller against one flange (vmap it yourself);
- `all_flange_contacts`: every roller against the four flanges, shape (Z, 4);
- `FlangeContact`: the result pytree.
"""

from ._contact import FLANGE_ORDER, FlangeContact, all_flange_contacts, roller_flange_contact

__all__ = ["FLANGE_ORDER", "FlangeContact", "all_flange_contacts", "roller_flange_contact"]
