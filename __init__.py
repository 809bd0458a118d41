"""Bounce: live indirect light in Blender's viewport and bakes, measured against Cycles.

Blender imports this file as the extension (bl_ext.<repo>.bounce); everything lives in addon/.
"""

from .addon import registration


def register():
    registration.register()


def unregister():
    registration.unregister()
