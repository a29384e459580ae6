"""What a left-hand side names, for one arm: the claim keys of :mod:`denavit.check` (quantity, index, frame …).

Readings follow the textbooks: Craig's left superscript names the reference frame (``{}^{0}T_{1}``, ``{}^{2}R_{3}``,
``{}^{3}J``, ``{}^{i}\\omega_{i}``); ``T_0^1``/``T_1^0`` (Spong, and its mirror) name the pose of the higher frame in
the lower one, the inverse being a second reading; ``A_i`` the link transform; ``p_x``, ``p_E``, ``p_{c2}`` the
end-effector position, one of its entries, a centre of mass; ``J_v``, ``J_\\omega``, ``J_{\\vartheta_3}``, ``J_{11}``
rows, a column, an entry.  A name that fits none of these is no reading (the equation is then not judged), and a
reading that is only a guess carries ``sure=False``: an "incorrect" under it becomes "ambiguous".
"""

from __future__ import annotations

import re
from dataclasses import replace
from typing import Any

from ..model import IDENTITY, DHRobot, JointType
from ._lhs import Symbol, frame_token
from ._masses import turns_about_z
from ._names_dyn import christoffel_reading, dynamics_reading, energy_reading
from ._reading_type import Reading, digit

__all__ = ["Reading", "read_name", "JOINT_LETTERS"]

JOINT_LETTERS = ("theta", "vartheta", "q", "Q", "heta")
_LINEAR = ("v", "L", "P", "p", "linear", "lin", "V")
_ANGULAR = ("\\omega", "omega", "w", "\\Omega", "R", "A", "o", "\\omega}", "ang", "W")
_TWIST = ("vartheta", "nu", "xi", "mathcal{V}", "mathcal V", "V_e", "xi_e", "nu_e")


def _joint_of_axis(k: int, robot: DHRobot) -> int:
    """Frame z_k carries joint k (modified DH) or joint k + 1 (standard DH)."""
    return k if robot.convention.value == "modified" else k + 1


def _frame(tok: str, robot: DHRobot) -> int | str | None:
    """A frame as written → its DH number; the end effector is the last DH frame when the arm has no tool."""
    f = frame_token(tok)
    if f == "base":
        return 0
    if f == "ee":
        return robot.n_rows if robot.tool == IDENTITY else "ee"
    if isinstance(f, int) and f > robot.n_rows:
        return None
    return f


def _transform(sym: Symbol, robot: DHRobot) -> Reading | None:
    """T, A, R, H with frames; ``R`` claims are the rotation block (the checker reads a 3×3 that way)."""
    n, kind = robot.n_rows, "rotation" if sym.base == "R" else "transform"
    if sym.base in ("A", "T") and re.fullmatch(r"\{?[ikn]\}?", sym.sub.strip()) and not sym.sup and not sym.pre_sup:
        return Reading({"quantity": "dh_matrix"}, "the general DH link matrix")
    if sym.base == "A" and sym.sub and not sym.sup and not sym.pre_sup:
        k = digit(sym.sub)
        if k is not None and 1 <= k <= n:
            return Reading({"quantity": "link_transform", "index": k}, f"A_{k}: the link transform of DH row {k}")
        return None
    if sym.pre_sup:
        a, b, ordered = sym.pre_sup, sym.sub or sym.pre_sub or sym.sup, True
    elif sym.sub and sym.sup:
        a, b, ordered = sym.sub, sym.sup, False
    elif sym.sub:
        k = digit(sym.sub)
        if k is None or not 1 <= k <= n or sym.base == "R":
            return None
        return Reading({"quantity": "transform", "from": 0, "to": k}, f"T_{k} read as T_0_{k}, the pose of frame {k} in "
                       "frame 0", ((({"quantity": "link_transform", "index": k}), f"A_{k}"),), sure=False)
    elif not sym.sub and not sym.sup and sym.base == "T":
        return Reading({"quantity": "end_effector"}, "T: the end-effector pose", sure=False)
    else:
        return None
    fa, fb = _frame(a, robot), _frame(b, robot)
    if isinstance(fa, str) and isinstance(fb, str) and fa != "ee" and fb != "ee":
        pair = {fa, fb}
        if pair in ({"i-1", "i"}, {"n-1", "n"}, {"k-1", "k"}, {"i", "i+1"}):
            return Reading({"quantity": "dh_matrix"}, "the general DH link matrix")
        return None
    if fa is None or fb is None:
        return None
    return _pose(fa, fb, ordered, kind, robot)


_POSITION_COLUMN = re.compile(r"\(?(?:1:3|:3|1:end-1),4\)?")


def _position_column(sym: Symbol, robot: DHRobot) -> Reading | None:
    """``T_4^0(1:3,4)`` (MATLAB's rows 1–3 of column 4): the position of frame 4's origin in the base frame."""
    if not _POSITION_COLUMN.fullmatch(sym.args.replace(" ", "")):
        return None
    pose = _transform(replace(sym, args=""), robot)
    if pose is None or not pose.sure:
        return None
    if pose.spec["quantity"] == "end_effector":
        return Reading({"quantity": "position"}, "the end-effector position (rows 1–3 of column 4 of the pose)")
    link_1 = pose.spec == {"quantity": "link_transform", "index": 1}  # A_1 = T_0_1
    if link_1 or pose.spec["quantity"] == "transform" and pose.spec["from"] == 0:
        k = 1 if link_1 else pose.spec["to"]
        return Reading({"quantity": "origin", "index": k}, f"the origin of DH frame {k} (rows 1–3 of column 4 of "
                       f"T_0_{k})", needs=("q",))
    return None


def _pose(fa: int | str, fb: int | str, ordered: bool, kind: str, robot: DHRobot) -> Reading | None:
    n = robot.n_rows
    ends = {fa, fb}
    if "ee" in ends:
        other = fb if fa == "ee" else fa
        if not isinstance(other, int):
            return None
        if other == 0 and (ordered is False or fa == 0):
            return Reading({"quantity": "end_effector"}, f"{kind} of the end effector in the base frame "
                           "(base · A_1 ⋯ A_N · tool)")
        return None
    if not isinstance(fa, int) or not isinstance(fb, int) or fa == fb:
        return None
    lo, hi = (fa, fb) if ordered else (min(fa, fb), max(fa, fb))
    if lo == 0 and hi == n and robot.base == IDENTITY and robot.tool == IDENTITY:
        return Reading({"quantity": "end_effector"}, f"T_0_{n}: the end-effector pose in the base frame"
                       + ("" if ordered else ""), (({"quantity": "transform", "from": n, "to": 0}, f"T_{n}_0, the "
                                                     "inverse"),) if not ordered else ())
    words = f"the {kind} of frame {hi} in frame {lo}" if kind == "transform" else f"R_{lo}_{hi}, the orientation " \
        f"of frame {hi} in frame {lo}"
    spec: dict[str, Any] = ({"quantity": "link_transform", "index": hi} if hi == lo + 1 else
                            {"quantity": "transform", "from": lo, "to": hi})
    label = (f"A_{hi} = T_{lo}_{hi}" if hi == lo + 1 else f"T_{lo}_{hi}") + f": {words}"
    if ordered:
        return Reading(spec, label)
    inverse = {"quantity": "transform", "from": hi, "to": lo}
    return Reading(spec, label, ((inverse, f"T_{hi}_{lo}, the inverse"),))


def _jacobian(sym: Symbol, robot: DHRobot) -> Reading | None:
    spec: dict[str, Any] = {"quantity": "det_jacobian" if sym.det else "jacobian"}
    words = ["det J" if sym.det else "J"]
    if sym.pre_sup:
        f = _frame(sym.pre_sup, robot)
        if f is None or isinstance(f, str) and f != "ee":
            return None
        spec["frame"] = "tool" if f == "ee" else f
        words.append(f"in the axes of frame {sym.pre_sup}" if f != "ee" else "in tool axes (Je)")
    sub = re.sub(r"\s+", "", sym.sub)
    sub = re.sub(r"^\\(?:vartheta|theta)(?=_|$)", "", sub).lstrip("_").strip("{}")
    sup = re.sub(r"\s+", "", sym.sup)
    if sup and sup not in ("z", "0") and not sym.pre_sup:
        return None
    if sub in ("", "q", "0", "\\vartheta", "\\theta", "\\nu", "g", "geo"):
        pass
    elif sub in ("e", "E", "b", "B", "ee", "n"):
        if "frame" in spec:
            return None
        spec["frame"] = "tool"
        words.append("in tool axes (Je)")
    elif sym.det and (sub in _LINEAR or sub in _ANGULAR):
        words.append(f"(J_{sub}: the rows are found among the square blocks)")
    elif sub in _LINEAR and not sym.det:
        spec["rows"] = "linear"
        words.append("linear rows (J_v)")
    elif sub in _ANGULAR and not sym.det:
        spec["rows"] = "angular"
        words.append("angular rows (J_ω)")
    else:
        k = digit(sub)
        two = re.fullmatch(r"(\d),?(\d)", sub)
        if k is not None and 1 <= k <= robot.dof and not sym.det:
            spec["column"] = k
            words.append(f"column {k}")
        elif two and robot.dof < 10 and not sym.det:
            spec["entry"] = [int(two.group(1)), int(two.group(2))]
            words.append(f"entry ({two.group(1)}, {two.group(2)})")
        else:
            return None
    if sym.transpose and not sym.det:
        spec["transpose"] = True
        words.append("transposed (Jᵀ)")
    return Reading(spec, " ".join(words), needs=("q",))


def _position(sym: Symbol, robot: DHRobot) -> Reading | None:
    sub = re.sub(r"[{}\s\\]|mathrm", "", sym.sub)
    if sym.pre_sup and sym.pre_sup.strip() not in ("0", "B", "W", "b", "w"):
        return None
    parts = [p for p in re.split(r"[,;]", sub) if p]
    axis = {"x": 1, "y": 2, "z": 3, "X": 1, "Y": 2, "Z": 3}
    com = re.fullmatch(r"[cCgG]_?(\d)", sub)
    if com:
        k = int(com.group(1))
        if not 1 <= k <= robot.n_rows:
            return None
        q = "com_velocity" if sym.dots == 1 else "com_position"
        return Reading({"quantity": q, "index": k}, f"the {'velocity' if sym.dots else 'position'} of the centre of "
                       f"mass of link {k}", needs=("q", "qd") if sym.dots else ("q",))
    if sym.dots == 2:
        return None
    if parts and parts[-1] in axis and all(p in ("E", "e", "T", "t", "ee", "tool", "0") for p in parts[:-1]):
        k = axis[parts[-1]]
        if sym.dots:
            return Reading({"quantity": "twist", "entry": k}, f"the end-effector velocity's {parts[-1]} entry",
                           needs=("q", "qd"))
        return Reading({"quantity": "position", "entry": k}, f"the end effector's {parts[-1]} coordinate", needs=("q",))
    if sub in ("", "E", "e", "ee", "T", "tool", "0E", "0e"):
        if sym.dots:
            return Reading({"quantity": "twist", "rows": "linear"}, "the end-effector linear velocity", needs=("q", "qd"))
        return Reading({"quantity": "position"}, "the end-effector position", sure=sub != "", needs=("q",))
    k = digit(re.sub(r"(?i)org$", "", sub))
    if k is not None and not sym.dots and 0 <= k <= robot.n_rows:
        return Reading({"quantity": "origin", "index": k}, f"the origin of DH frame {k} (base axes)", needs=("q",))
    return None


def _axis(sym: Symbol, robot: DHRobot, rhs: str) -> Reading | None:
    """``z_1 = [⋯]``, ``\\hat{z}_1``, ``e_{z_1}``, ``{}^0\\hat{Z}_2``: the z axis of DH frame k in base axes, a vector
    — the axis of joint k + 1 (standard DH: z_{i−1} carries joint i) or of joint k (modified DH: z_i)."""
    base, sub = sym.base, sym.sub.strip("{} ")
    if base == "e" and re.fullmatch(r"z_?\{?\d\}?", sub):
        base, sub = "z", sub.lstrip("z_{").rstrip("}")
    if base not in ("z", "Z", "hatz", "hatZ") or sym.dots or sym.args or sym.sup or sym.pre_sup not in ("", "0"):
        return None
    k = digit(sub) if sub else None
    if k is None or not ("\\begin" in rhs or rhs.lstrip()[:1] in "[(") or "=" in rhs:
        return None
    joint = k + 1 if robot.convention.value == "standard" else k
    if not 1 <= joint <= robot.dof:
        return None
    return Reading({"quantity": "joint_axis", "index": joint}, f"z_{k}: the axis of joint {joint} (base axes)",
                   needs=("q",))


def _coordinate(sym: Symbol, robot: DHRobot) -> Reading | None:
    """``x``, ``y``, ``z`` and their rates: the end effector's coordinates (a guess: x may name something else)."""
    k = {"x": 1, "y": 2, "z": 3}[sym.base]
    if sym.sub or sym.sup or sym.pre_sup:
        return None
    if sym.dots == 1:
        return Reading({"quantity": "twist", "entry": k}, f"the end-effector velocity's {sym.base} entry",
                       sure=robot.dof <= 4, needs=("q", "qd"))
    if sym.dots == 0:
        return Reading({"quantity": "position", "entry": k}, f"the end effector's {sym.base} coordinate",
                       sure=robot.dof <= 4, needs=("q",))
    return None


def _propagated(sym: Symbol, robot: DHRobot) -> Reading | None:
    """ⁱωᵢ, ⁱvᵢ, ⁱfᵢ, ⁱnᵢ: velocity and force propagation, in frame i's own axes."""
    q = {"omega": "omega", "w": "omega", "v": "velocity", "f": "force", "n": "moment"}[sym.base]
    if sym.dots or not sym.pre_sup or not sym.sub:
        return None
    a, b = _frame(sym.pre_sup, robot), _frame(sym.sub, robot)
    if a is None or a != b:
        return None
    idx: Any = "e" if a == "ee" else a
    if not (idx == "e" or isinstance(idx, int)):
        return None
    words = {"omega": "angular velocity", "velocity": "velocity of the origin", "force": "force", "moment": "moment"}
    spec: dict[str, Any] = {"quantity": q, "index": idx}
    return Reading(spec, f"{{}}^{sym.pre_sup}{sym.base}_{sym.sub}: the {words[q]} of frame {sym.sub} in its own axes",
                   needs=("q", "qd") if q in ("omega", "velocity") else ("q", "wrench"))


def read_name(sym: Symbol, robot: DHRobot, rhs: str = "") -> Reading | None:
    """The reading of a left-hand side for ``robot`` (``rhs`` decides between look-alikes such as ``L``)."""
    b = sym.base
    dynamic = bool(re.search(r"\\dot|\\ddot|m_|I_|\bg\b", rhs))
    if b in ("T", "A", "R", "H") and not sym.dots and not sym.det:
        if b == "T" and dynamic and not (sym.sub or sym.sup or sym.pre_sup):
            return energy_reading(sym)
        if sym.args and b != "R":
            return _position_column(sym, robot)
        return _transform(sym, robot)
    if b == "J" or (sym.det and b == "J"):
        return _jacobian(sym, robot)
    if b in ("P", "V", "U") and dynamic and not (sym.sub or sym.pre_sup or sym.dots):
        return energy_reading(sym)
    if b in ("p", "P", "o", "O") and not sym.det:
        return _position(sym, robot)
    axis = _axis(sym, robot, rhs)
    if axis is not None:
        return axis
    if b in ("x", "y", "z"):
        return _coordinate(sym, robot)
    rate = _rate_row(sym, robot)
    if rate is not None:
        return rate
    if b in ("omega", "w", "v", "f", "n"):
        if not sym.pre_sup and b in ("omega", "v") and not sym.sub:
            rows = "angular" if b == "omega" else "linear"
            return Reading({"quantity": "twist", "rows": rows}, f"the end effector's {'angular' if rows == 'angular' else 'linear'}"
                           " velocity", needs=("q", "qd"))
        return _propagated(sym, robot)
    if b == "tau":
        k = digit(sym.sub) if sym.sub else None
        if sym.sub and (k is None or not 1 <= k <= robot.dof):
            return None
        qty = "equations_of_motion" if "\\ddot" in rhs else "torques"
        spec: dict[str, Any] = {"quantity": qty}
        if k is not None:
            spec["entry"] = k
        words = "the joint torques" if qty == "torques" else "the equations of motion τ = M q̈ + c + g"
        return Reading(spec, words + (f", entry {k}" if k else ""),
                       needs=("q", "wrench") if qty == "torques" else ("q", "qd", "qdd"))
    rate = _rate_row(sym, robot)
    if rate is not None:
        return rate
    if b in _TWIST and not sym.sub and not sym.pre_sup:
        return Reading({"quantity": "twist"}, "the end-effector twist (v, ω) = J q̇", needs=("q", "qd"))
    gravity_rhs = bool(re.search(r"\bg\b", rhs)) and "m_" in rhs
    if b in ("d", "D", "phi") and (b != "phi" or gravity_rhs) and "m_" in rhs and not sym.pre_sup:
        b = {"d": "M", "D": "M", "phi": "g"}[b]  # Spong's d_ij (the inertia matrix) and φ_k (gravity), by its value
        sym = replace(sym, base=b)
    if b in ("c", "Gamma") and robot.has_dynamics and not re.match(r"\s*\\?cos", rhs):
        christoffel = christoffel_reading(sym, robot, rhs)
        if christoffel is not None:
            return christoffel
    if b in ("M", "G", "g", "c", "C", "h"):
        return dynamics_reading(sym, robot, gravity_rhs=gravity_rhs)
    if b in ("K", "P", "U", "V", "L", "mathcal{L}") and (dynamic or b in ("K",)):
        return energy_reading(sym)
    if b in ("phi", "varphi", "psi") and not (sym.sub or sym.sup or sym.pre_sup or sym.dots) \
            and re.search(r"theta|\bq_|θ", rhs) and turns_about_z(robot):
        plain = robot.base == IDENTITY and robot.tool == IDENTITY  # else φ may be the last link's, not the tool's
        return Reading({"quantity": "heading"}, "the heading φ of the end effector (its turn about z)", sure=plain)
    return None


def joint_of(sym: Symbol, robot: DHRobot) -> int | None:
    """The joint a left-hand side such as ``\\theta_2``, ``q_3``, ``d_3`` (a prismatic joint) names, if any."""
    if sym.dots or sym.pre_sup or sym.sup or sym.args or sym.det:
        return None
    k = digit(sym.sub) if sym.sub else None
    if k is None or not 1 <= k <= robot.dof:
        return None
    if sym.base in JOINT_LETTERS:
        return k
    if sym.base == "d" and robot.joint_types[k - 1] is JointType.PRISMATIC:
        params = {p for p, _ in robot.parameters}
        return None if f"d{k}" in params else k
    return None


def _rate_row(sym: Symbol, robot: DHRobot) -> Reading | None:
    """``\\dot\\theta_z``, ``\\omega_z``, ``\\dot\\alpha`` (the heading rate of a planar arm): one angular twist row."""
    axis = re.sub(r"[{}\s]", "", sym.sub)
    if sym.pre_sup or sym.sup:
        return None
    if sym.base in ("theta", "phi", "psi") and sym.dots == 1 and axis in ("x", "y", "z"):
        k = {"x": 4, "y": 5, "z": 6}[axis]
    elif sym.base in ("omega", "w") and sym.dots == 0 and axis in ("x", "y", "z"):
        k = {"x": 4, "y": 5, "z": 6}[axis]
    elif sym.base in ("alpha", "phi", "psi", "varphi") and sym.dots == 1 and not axis and robot.dof <= 4:
        return Reading({"quantity": "twist", "entry": 6}, "the rate of the heading angle (ω_z)", sure=False,
                       needs=("q", "qd"))
    else:
        return None
    return Reading({"quantity": "twist", "entry": k}, f"the end effector's angular velocity ω_{axis}",
                   needs=("q", "qd"))
