"""Tables, figures and the claims ledger from the collected evaluation and recovery results."""
