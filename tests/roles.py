"""The shipped presets' roles (config/trees.yaml ``presets.<tree>.role``), for tests that ask
the ledger about the shipped trees."""

from pathlib import Path

import yaml

from physgs.report.claim_cells import roles_of

_CFG = yaml.safe_load((Path(__file__).resolve().parents[1] / "config" / "trees.yaml").read_text())
#: tree -> its role, for every shipped preset
ROLES = roles_of(_CFG["presets"], list(_CFG["presets"]))
