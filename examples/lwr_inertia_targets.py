"""Write identified.inertia of examples/lwr.yaml: pi_inertia of the paper's own final solution.

The paper does not print its identified inertia coefficients pi_hat_m; following the paper's
own numbers, they are rebuilt from its final solution (examples/lwr_paper_solution.yaml:
Tables II and IV, eq. 20 don't-care values, eq. 15 identities) through dyngen's pi_inertia(p).
Run: python examples/lwr_inertia_targets.py  (rewrites the block between the markers).
"""

from pathlib import Path

from dyngen.description import load_robot
from dyngen.emission.coefficients import grouped_text
from dyngen.data.parameters_file import read_link_parameters
from dyngen.generate import build
from dyngen.parameters import PER_LINK, standard_from_dynamic, standard_name

HERE = Path(__file__).resolve().parent
BEGIN, END = "  # BEGIN inertia targets (examples/lwr_inertia_targets.py)\n", "  # END inertia targets\n"


def main():
    robot = load_robot(HERE / "lwr.yaml")
    bases, _ = build(robot)
    base = bases["inertia"]
    s = standard_from_dynamic(read_link_parameters(HERE / "lwr_paper_solution.yaml", robot.dof))
    names = [standard_name(i + 1, k) for i in range(robot.dof) for k in range(PER_LINK)]
    lines = [BEGIN, "  # The paper does not print pi_hat_m: these are pi_inertia(p) of the paper's own final solution\n  # (examples/lwr_paper_solution.yaml: Tables II, IV, eq. 20, eq. 15), by examples/lwr_inertia_targets.py.\n  inertia:\n"]
    for row in base.K:
        value = float(sum(float(k) * x for k, x in zip(row, s)))
        lines.append(f'    - {{coefficient: "{grouped_text(row, names)}", value: {value!r}}}\n')
    lines.append(END)
    text = (HERE / "lwr.yaml").read_text()
    start, end = text.index(BEGIN), text.index(END) + len(END)  # replaced in place
    (HERE / "lwr.yaml").write_text(text[:start] + "".join(lines) + text[end:])


if __name__ == "__main__":
    main()
