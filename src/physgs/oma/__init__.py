"""Output-only modal analysis of the training video (issue 42, docs/blind.md)."""
