"""What joins the stages: run (lockstep), cue, suite and its process pool."""
