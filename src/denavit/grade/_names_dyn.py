"""Names of dynamics results on a report's left-hand side: M, g, c, C with an entry, Spong's Christoffel symbols
c_ijk, the energies K, P, L.  Moved from ``_names.py`` (code unchanged, names made public for it)."""

from __future__ import annotations

import re
from typing import Any

from ..model import DHRobot
from ._lhs import Symbol
from ._reading_type import Reading, digit

__all__ = ["dynamics_reading", "christoffel_reading", "energy_reading"]


def dynamics_reading(sym: Symbol, robot: DHRobot, gravity_rhs: bool = False) -> Reading | None:
    """M, g, c, C with an entry; ``g_2`` alone only when its value has g and a mass in it (else a cosine-like
    shorthand or the gravity's magnitude)."""
    names = {"M": ("mass_matrix", "the mass matrix M(q)"), "G": ("gravity", "the gravity torques g(q)"),
             "g": ("gravity", "the gravity torques g(q)"), "c": ("coriolis", "the Coriolis/centrifugal torques c(q, q̇)"),
             "C": ("coriolis_matrix", "the Coriolis matrix C(q, q̇)"), "h": ("coriolis", "c(q, q̇)")}
    if sym.base not in names or sym.pre_sup or sym.dots:
        return None
    if sym.base in ("g", "c", "C", "h", "G") and not sym.args and not (sym.base in ("g", "G") and gravity_rhs):
        return None
    qty, words = names[sym.base]
    spec: dict[str, Any] = {"quantity": qty}
    sub = re.sub(r"[{}\s]", "", sym.sub)
    if sub:
        two = re.fullmatch(r"(\d),?(\d)", sub)
        k = digit(sub)
        if two and qty in ("mass_matrix", "coriolis_matrix"):
            spec["entry"] = [int(two.group(1)), int(two.group(2))]
            words += f", entry ({two.group(1)}, {two.group(2)})"
        elif k is not None and qty in ("gravity", "coriolis") and 1 <= k <= robot.dof:
            spec["entry"] = k
            words += f", entry {k}"
        else:
            return None
    return Reading(spec, words, needs=("q",))


def christoffel_reading(sym: Symbol, robot: DHRobot, rhs: str) -> Reading | None:
    """``c_{121}`` (Spong's c_ijk, the row index of C last) or ``\\Gamma^1_{21}``: a Christoffel symbol of M; the
    other order, the row index first (``\\Gamma_{ijk}`` of Murray, Li, Sastry), is the second reading.  Sure only
    when the value has a mass or a derivative in it, or is 0 (``c_{123} = c_{12} c_3 - s_{12} s_3`` is a cosine)."""
    sub, sup = re.sub(r"[{}\s,]", "", sym.sub), re.sub(r"[{}\s,]", "", sym.sup)
    if sym.pre_sup or sym.dots or sym.args or sym.pre_sub:
        return None
    idx = sub + sup if sym.base == "Gamma" and len(sup) == 1 and len(sub) == 2 else sub if not sup else ""
    if len(idx) != 3 or not idx.isdigit() or not all(1 <= int(d) <= robot.dof for d in idx):
        return None
    i, j, k = map(int, idx)
    other = ({"quantity": "christoffel", "entry": [j, k, i]}, f"the Christoffel symbol with the row index first "
             f"(Spong's c_{j}{k}{i})")
    sure = bool(re.search(r"m_|\\partial", rhs)) or rhs.strip() == "0"
    return Reading({"quantity": "christoffel", "entry": [i, j, k]}, f"Spong's Christoffel symbol c_{i}{j}{k} of M",
                   (other,) if len({i, j, k}) > 1 else (), sure=sure, needs=("q",))


def energy_reading(sym: Symbol) -> Reading | None:
    names = {"K": ("kinetic_energy", "the kinetic energy K"), "T": ("kinetic_energy", "the kinetic energy"),
             "P": ("potential_energy", "the potential energy"), "U": ("potential_energy", "the potential energy"),
             "V": ("potential_energy", "the potential energy"), "L": ("lagrangian", "the Lagrangian L = K − P"),
             "mathcal{L}": ("lagrangian", "the Lagrangian")}
    if sym.base not in names or sym.sub or sym.sup or sym.pre_sup or sym.dots:
        return None
    qty, words = names[sym.base]
    return Reading({"quantity": qty}, words, needs=("q",))
