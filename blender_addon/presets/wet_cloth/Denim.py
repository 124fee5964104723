import bpy
s = bpy.context.object.wet_cloth

s.density = 0.4
s.air_drag = 0.02
s.stretch = 3000.0
s.bend = 0.0001
s.damping = 0.08
s.thickness = 0.008
s.friction = 0.6
s.adhesion = 20.0
s.spread = 0.3
s.wet_friction = 0.1
s.wet_grip = 40.0
s.wet_mass_gain = 0.7
s.wet_softening = 0.2
s.wicking = 0.0
s.drying = 0.0
