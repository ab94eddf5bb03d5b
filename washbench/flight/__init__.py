"""The JSBSim side: fdm set-up, scripted pilot, crash monitor, recorder and the fly loop."""
