"""The thesis's planners (chapters 5–6) and an exact optimum, as functions and policies."""
