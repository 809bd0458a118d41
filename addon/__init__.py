"""Bounce: indirect light for Blender's viewport and bakes.

`addon.engine` is the Blender-free core; `addon.bridge` is the Blender side. Blender-specific
modules are imported lazily so `import addon.engine` works without bpy.
"""
