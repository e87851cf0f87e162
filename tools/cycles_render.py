# Renders one OpenVDB density volume in Blender's Cycles for tools/cycles_referee.py; runs inside Blender:
#   blender -b --factory-startup --python tools/cycles_render.py -- PARAMS.json
# PARAMS.json (written by the referee) holds the volume, the camera, the sun and the render settings; the image is
# written as float32 .npy, shape (height, width, 3), row 0 at the top (cloudbench's convention), linear radiance.
# PARAMS.json with "convert": [[exr, npy], ...] only converts those EXR files (cloudbench's frames) the same way.
#
# The set-up matches cloudbench's exact reference render (docs/accuracy.md, "Cycles as an outside referee"):
# - the volume moved by half a voxel toward -x, -y, -z (`volume_offset`, set by the referee): Blender reads a VDB's
#   voxel (i, j, k) as the cell [i, i + 1] of index space, centred at i + 1/2, where OpenVDB (and the file's
#   transform) put its centre at i;
# - the density: the grid `q` times sigma (Principled Volume, albedo 1, no absorption, no emission), multiplied by a
#   mask that is 1 inside the grid's box and 0 outside, since cloudbench's trilinear field stops at the box faces
#   while a VDB's trilinear field runs on half a voxel past them;
# - the sun: a lamp of angle 0 along `sun_direction` (toward the sun), strength 4 pi times cloudbench's sun
#   intensity (Cycles' phase functions integrate to 1 over the sphere, cloudbench's to 4 pi), its colour per channel;
# - Henyey-Greenstein anisotropy g; a black world (no background, no ambient light);
# - the camera: cloudbench's look-at pinhole (vertical field of view, up +z), a box filter of the least width
#   Blender allows (0.01 px), so each pixel is sampled at its centre as cloudbench's rays are;
# - no denoising, no adaptive sampling, no light tree, a fixed sample count and seed; volume bounces as asked
#   (0: single scattering), the ray-marching step `step_rate` times the voxel size.
import json
import math
import sys

import bpy
import numpy as np


def main(params):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = params["samples"]
    cycles.seed = params["seed"]
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.max_bounces = max(params["volume_bounces"], 0)
    cycles.volume_bounces = params["volume_bounces"]
    cycles.diffuse_bounces = cycles.glossy_bounces = cycles.transmission_bounces = 0
    cycles.transparent_max_bounces = 64  # the volume's bounding mesh: each crossing counts as one
    cycles.volume_step_rate = params["step_rate"]
    cycles.volume_max_steps = params["max_steps"]
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 0.01
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.caustics_reflective = cycles.caustics_refractive = True
    if hasattr(cycles, "use_light_tree"):
        cycles.use_light_tree = False
    scene.render.threads_mode = "FIXED" if params.get("threads") else "AUTO"
    if params.get("threads"):
        scene.render.threads = params["threads"]
    scene.render.resolution_x = params["width"]
    scene.render.resolution_y = params["height"]
    scene.render.resolution_percentage = 100
    scene.render.use_persistent_data = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.display_settings.display_device = "None"
    scene.sequencer_colorspace_settings.name = "Non-Color"

    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    volume = bpy.data.volumes.new("clouds")
    volume.filepath = params["vdb"]
    volume.grids.load()
    obj = bpy.data.objects.new("clouds", volume)
    obj.location = params.get("volume_offset", [0.0, 0.0, 0.0])
    scene.collection.objects.link(obj)
    obj.data.materials.append(make_material(params))

    sun_data = bpy.data.lights.new("sun", type="SUN")
    sun_data.angle = 0.0
    sun_data.energy = 4.0 * math.pi * params["sun_intensity"]
    sun_data.color = params["sun_color"]
    if hasattr(sun_data, "cycles"):
        sun_data.cycles.cast_shadow = True
    sun = bpy.data.objects.new("sun", sun_data)
    scene.collection.objects.link(sun)
    # A sun lamp shines along its local -z: point that axis away from the sun.
    s = params["sun_direction"]
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = vector_to_quaternion([-s[0], -s[1], -s[2]])

    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(params["fov_deg"])
    cam_data.clip_start = params["near"]
    cam_data.clip_end = params["far"]
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    cam.matrix_world = look_at_matrix(params["eye"], params["target"], params["up"])

    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = params["exr"]
    bpy.ops.render.render(write_still=True)

    exr_to_npy(params["exr"], params["npy"])


def exr_to_npy(exr, npy):
    image = bpy.data.images.load(exr)
    width, height = image.size
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(height, width, image.channels)
    np.save(npy, np.ascontiguousarray(pixels[::-1, :, :3]))  # Blender's row 0 is the bottom


def make_material(params):
    """Principled Volume of density sigma q(p) box(p), colour 1 (albedo 1), anisotropy g."""
    material = bpy.data.materials.new("cloud")
    material.use_nodes = True
    material.cycles.volume_interpolation = "LINEAR"
    material.cycles.homogeneous_volume = False
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    volume = nodes.new("ShaderNodeVolumePrincipled")
    volume.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    volume.inputs["Anisotropy"].default_value = params["g"]
    volume.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    volume.inputs["Emission Strength"].default_value = 0.0
    volume.inputs["Blackbody Intensity"].default_value = 0.0
    volume.inputs["Density Attribute"].default_value = ""
    attribute = nodes.new("ShaderNodeAttribute")
    attribute.attribute_name = params["grid"]
    geometry = nodes.new("ShaderNodeNewGeometry")
    # The box [lo, hi] (world units): product over axes of (p >= lo) (p <= hi).
    separate = nodes.new("ShaderNodeSeparateXYZ")
    links.new(geometry.outputs["Position"], separate.inputs[0])
    factor = math_node(nodes, "MULTIPLY", None, params["sigma"])
    links.new(attribute.outputs["Fac"], factor.inputs[0])
    product = factor
    for axis, name in enumerate("XYZ"):
        for op, bound in (("GREATER_THAN", params["box_lo"][axis]), ("LESS_THAN", params["box_hi"][axis])):
            # GREATER_THAN gives p > bound; the faces themselves carry no volume, so open or closed is the same.
            test = math_node(nodes, op, None, bound)
            links.new(separate.outputs[name], test.inputs[0])
            both = math_node(nodes, "MULTIPLY", None, None)
            links.new(product.outputs[0], both.inputs[0])
            links.new(test.outputs[0], both.inputs[1])
            product = both
    links.new(product.outputs[0], volume.inputs["Density"])
    links.new(volume.outputs["Volume"], output.inputs["Volume"])
    return material


def math_node(nodes, operation, a, b):
    node = nodes.new("ShaderNodeMath")
    node.operation = operation
    if a is not None:
        node.inputs[0].default_value = a
    if b is not None:
        node.inputs[1].default_value = b
    return node


def vector_to_quaternion(direction):
    """The rotation that takes -z to `direction` (a lamp's or a camera's view axis)."""
    from mathutils import Vector
    return Vector(direction).normalized().to_track_quat("-Z", "Y")


def look_at_matrix(eye, target, up):
    """cloudbench's look-at (core/math/Camera.cpp): forward = target - eye, right = forward x up, up' = right x
    forward; a Blender camera looks down its local -z with +y up."""
    from mathutils import Matrix, Vector
    forward = (Vector(target) - Vector(eye)).normalized()
    right = forward.cross(Vector(up))
    if right.length < 1e-6 * Vector(up).length:
        for fallback in ((0, 1, 0), (1, 0, 0)):
            right = forward.cross(Vector(fallback))
            if right.length > 1e-6:
                break
    right.normalize()
    true_up = right.cross(forward)
    m = Matrix.Identity(4)
    for i in range(3):
        m[i][0], m[i][1], m[i][2], m[i][3] = right[i], true_up[i], -forward[i], eye[i]
    return m


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:]
    with open(argv[0]) as f:
        params = json.load(f)
    if "convert" in params:
        for exr, npy in params["convert"]:
            exr_to_npy(exr, npy)
    else:
        main(params)
