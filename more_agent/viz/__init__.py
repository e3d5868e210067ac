"""Pictures of maps, scene graphs and trajectories, and the HTML evaluation report."""
