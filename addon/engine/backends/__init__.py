"""GPU backends: one narrow interface (base.py), implemented on moderngl and on Blender's gpu module."""
