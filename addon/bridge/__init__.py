"""The Blender side of Bounce: capture, Blender's gpu backend, viewport, bake, images."""
