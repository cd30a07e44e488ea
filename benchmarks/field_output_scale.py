"""fit_recipe.py with the learned fields' outputs scaled: does the output's scale limit the fit?

A recipe candidate (SPEC: "the scale of the field's outputs relative to the scene"), measured
and not kept (README, *How the training recipe was chosen*). Every head of every learned field
(position offset in scene units; for Deformable-3DGS also the rotation and log-scale offsets) is
multiplied by ``--scale``. Under Adam a head's step is about the learning rate whatever its
gradient, so the scale sets how far one step moves a Gaussian: the medium tree's true swing is
about 1 cm rms against a 2.2 m scene half-extent. Every other argument goes to fit_recipe.py,
so it scores only training-window frames.

    python benchmarks/field_output_scale.py --scale 0.25 results/testbed/medium --models mlp_wind
"""

from __future__ import annotations

import argparse

import fit_recipe  # its sibling: run as python benchmarks/<this>.py
from physgs.models.fields import DeformationField


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, add_help=False, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--scale", type=float, default=1.0, help="factor on every field output")
    args, rest = ap.parse_known_args()
    forward = DeformationField.forward

    def scaled(self, x):  # x [N, in_dim]
        return {name: args.scale * out for name, out in forward(self, x).items()}

    DeformationField.forward = scaled
    fit_recipe.main(rest)


if __name__ == "__main__":
    main()
