"""The pilot-model stage: a multimodal pilot model that closes the loop through the washout.

A pilot model flies a compensatory tracking task (:mod:`washbench.pilot.task`) in JSBSim: it sees the displayed
error, feels the simulator pilot's motion through the project's vestibular models and moves the stick. Its
interface (:mod:`washbench.pilot.model`) sits beside the washout's (:mod:`washbench.cueing.algorithm`) and the
platform's (:mod:`washbench.platform.model`); the built-in model is :mod:`washbench.pilot.multimodal`, its
parameters :mod:`washbench.pilot.params`, its adaptation to a motion condition :mod:`washbench.pilot.adapt`.
docs/pilot-model.md gives every equation and value with its reference.
"""
