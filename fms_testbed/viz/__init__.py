"""Plots. No backend is set at import; plot functions take data and return figures, and saving is the
caller's business."""
