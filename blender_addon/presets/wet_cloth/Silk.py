import bpy
s = bpy.context.object.wet_cloth

s.density = 0.06
s.air_drag = 0.02
s.stretch = 600.0
s.bend = 2e-06
s.damping = 0.05
s.thickness = 0.002
s.friction = 0.3
s.adhesion = 40.0
s.spread = 0.6
s.wet_friction = 0.03
s.wet_grip = 80.0
s.wet_mass_gain = 0.8
s.wet_softening = 0.4
s.wicking = 0.0
s.drying = 0.0
