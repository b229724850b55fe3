"""PPO agents trained on gait discovery and their comparison against the baselines."""
