import bpy
s = bpy.context.object.wet_cloth

s.density = 0.15
s.air_drag = 0.02
s.stretch = 1000.0
s.bend = 1e-05
s.damping = 0.05
s.thickness = 0.005
s.friction = 0.5
s.adhesion = 30.0
s.spread = 0.5
s.wet_friction = 0.05
s.wet_grip = 60.0
s.wet_mass_gain = 1.0
s.wet_softening = 0.3
s.wicking = 0.0
s.drying = 0.0
