"""Checking a student's hand derivation of a planar two-link arm.

Run: ``python examples/checking_claims.py``.  Claims are what a person wrote (LaTeX or plain formulas, in the
joint variables); ``check_claims`` says for each whether it is correct, and for a wrong one which entries
differ, a counterexample and a hint.  The same claims as a file: ``denavit check planar2r claims.yaml``
(see docs/claims.md and examples/claims/).
"""

import denavit
from denavit.check import check_claims, verdicts_text

robot = denavit.load_robot("planar2r")
claims = [
    {"id": "position", "quantity": "position",
     "value": r"\begin{pmatrix} L_1 c_1 + L_2 c_{12} \\ L_1 s_1 + L_2 s_{12} \\ 0 \end{pmatrix}"},
    {"id": "position with a sign slip", "quantity": "position",
     "value": [r"L_1 \cos\theta_1 + L_2 \cos(\theta_1 + \theta_2)", r"L_1 \sin\theta_1 - L_2 \sin(\theta_1 + \theta_2)",
               "0"]},
    {"id": "J0 linear rows", "quantity": "jacobian", "rows": "linear",
     "value": r"\begin{bmatrix} -L_1 s_1 - L_2 s_{12} & -L_2 s_{12} \\ L_1 c_1 + L_2 c_{12} & L_2 c_{12} \\ 0 & 0 \end{bmatrix}"},
]
result = check_claims(robot, claims)
print(verdicts_text(result))
verdicts = {v.id: v.verdict for v in result.verdicts}
assert verdicts == {"position": "correct", "position with a sign slip": "incorrect", "J0 linear rows": "correct"}
slip = result.verdicts[1]
assert [list(e["entry"]) for e in slip.to_json()["entries"]] == [[2]]  # entries count from 1: y is wrong
