"""Output-only modal analysis of the training video (docs/blind.md)."""
