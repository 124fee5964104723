import bpy
s = bpy.context.object.wet_cloth

s.density = 0.45
s.air_drag = 0.02
s.stretch = 800.0
s.bend = 5e-05
s.damping = 0.1
s.thickness = 0.01
s.friction = 0.8
s.adhesion = 35.0
s.spread = 0.4
s.wet_friction = 0.05
s.wet_grip = 70.0
s.wet_mass_gain = 2.0
s.wet_softening = 0.4
s.wicking = 0.0
s.drying = 0.0
