# Installs and enables the keyframe cloth add-on in the user's Blender preferences:
#   blender -b --python scripts/blender/install.py
# (or Edit > Preferences > Add-ons > Install... and pick scripts/blender/keyframe_cloth.py).
import os

import bpy

addon = os.path.join(os.path.dirname(os.path.abspath(__file__)), "keyframe_cloth.py")
bpy.ops.preferences.addon_install(filepath=addon, overwrite=True)
bpy.ops.preferences.addon_enable(module="keyframe_cloth")
bpy.ops.wm.save_userpref()
print("keyframe cloth installed into", bpy.utils.user_resource('SCRIPTS', path="addons"))
