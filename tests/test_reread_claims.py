"""tools/reread_claims.py: a committed ledger re-read with today's tests, without a new run."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pandas as pd

from roles import ROLES

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("reread", ROOT / "tools" / "reread_claims.py")
reread = importlib.util.module_from_spec(spec)
spec.loader.exec_module(reread)


def test_a_committed_interval_of_p_minus_six_rereads_as_not_flat(tmp_path):
    """The one-instance record's medium row (p = -6.07 [-9.70, -2.44], five seeds) held under
    the one-sided test; re-read under the band it fails. Its recovery records are not committed:
    the verdict comes from the row's own interval."""
    (tmp_path / "tables").mkdir()
    pd.DataFrame(
        [
            {
                "id": "decay_rate_flat/medium",
                "verdict": "holds",
                "measured": -6.07445,
                "ci_low": -9.70432,
                "ci_high": -2.44458,
                "seeds": 5,
            },
            {
                "id": "damping_not_recovered/medium",
                "verdict": "holds",
                "measured": 1.52,
                "ci_low": 1.49,
                "ci_high": 1.55,
                "seeds": 5,
            },
        ]
    ).to_csv(tmp_path / "claims.csv", index=False)
    df = reread.reread(tmp_path, ROLES).set_index("id")
    assert df.loc["decay_rate_flat/medium", "new"] == "fails"
    assert df.loc["decay_rate_flat/medium", "from"] == "interval"
    # the paper's medium zeta_hat 0.125-0.142 against 0.08: offsets 0.5625-0.775, below [1.49, 1.55]
    r = df.loc["damping_not_recovered/medium"]
    assert r["new"] == "holds" and r["paper_in_interval"] == "outside"
