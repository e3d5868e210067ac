"""Pictures of maps, scene graphs, trajectories and sensor frames: drawing only (the reports live in eval)."""
