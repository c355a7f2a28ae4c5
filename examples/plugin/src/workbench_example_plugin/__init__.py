"""An example plugin of the lateral-control workbench: a controller (`lateral-pd`) and a vehicle (`example-kart`)."""
