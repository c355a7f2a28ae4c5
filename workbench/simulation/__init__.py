"""The simulation layer: scenarios, the speed profile and speed control, the closed-loop simulator, its result,
metrics and run plots. It imports the base and the vehicles, and drives any controller through the interface of
`control_interface.py`."""
