"""Blender-free core of Bounce: scene model, configs, SH, shader loading, GPU backends, passes.

Nothing under this package may import bpy, gpu, mathutils or bmesh (a test enforces it).
"""
