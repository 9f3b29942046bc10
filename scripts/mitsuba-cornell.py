#!/usr/bin/env python3
"""Render Bitterli's pbrt-v4 Cornell box with Mitsuba 3, as a reference for englobe's render.

    python3 scripts/mitsuba-cornell.py SCENE.pbrt OUT.exr [--spp N] [--seed S] [--variant V]

Mitsuba 3 does not read pbrt files, so this script reads the small subset of pbrt-v4 that the
Cornell box uses (Transform, Camera "perspective" fov, Film resolution, Sampler pixelsamples,
Integrator maxdepth, PixelFilter "triangle" radius or "box", MakeNamedMaterial/NamedMaterial "diffuse"
with an rgb reflectance, Shape "trianglemesh" P and indices, AttributeBegin/End and
AreaLightSource "diffuse" rgb L) and refuses anything else by name, so that the two renderers
are known to see the same scene. The translation, each point stated where the two differ:

- pbrt's `Transform` is the world-to-camera matrix (its last four numbers are the translation);
  pbrt's camera space is left-handed (x right, y up, z forward) and Mitsuba's right-handed
  (x left), so Mitsuba's camera-to-world is the inverse with its x axis negated.
- pbrt's fov is on the shorter image axis: Mitsuba's `fov_axis = "smaller"`.
- pbrt's `maxdepth` counts bounces (1 = direct light only); Mitsuba's `max_depth` counts path
  vertices (2 = direct light only), so Mitsuba gets maxdepth + 1.
- pbrt's triangle filter of radius r is Mitsuba's `tent` of radius r; pbrt's box of radius 0.5
  is Mitsuba's `box`. Mitsuba adds each sample to every pixel its filter reaches (splatting), pbrt
  and englobe to one pixel, the filter drawn as the sample's offset, so with a filter wider than a
  pixel Mitsuba's pixels average more samples and are less noisy, and correlated.
- pbrt's diffuse material reflects on both sides: Mitsuba's `diffuse` inside `twosided`.
- pbrt's area light emits on the side its geometric normal points to, as Mitsuba's `area` does.
- The `rgb` variant renders in linear RGB, as englobe does (pbrt-v4 renders spectrally).
"""

import argparse
import os
import re
import struct
import sys
import tempfile


def tokens(text):
    """pbrt's tokens: quoted strings, brackets, and bare words or numbers; comments dropped."""
    for m in re.finditer(r'"([^"]*)"|(\[|\])|#[^\n]*|([^\s\[\]"#]+)', text):
        if m.group(1) is not None:
            yield ("str", m.group(1))
        elif m.group(2) is not None:
            yield (m.group(2), m.group(2))
        elif m.group(3) is not None:
            yield ("word", m.group(3))


def read_scene(path):
    """The directives of a pbrt file as (name, [args], {param: values}); parameters are
    '"type name" [values]' pairs after the directive's own quoted arguments."""
    toks = list(tokens(open(path, encoding="utf-8").read()))
    out, i = [], 0
    while i < len(toks):
        kind, name = toks[i]
        if kind != "word":
            sys.exit(f"{path}: expected a directive, found {name!r}")
        i += 1
        args, params = [], {}
        if name == "Transform":
            assert toks[i][0] == "[", "Transform expects [16 numbers]"
            i += 1
            while toks[i][0] != "]":
                args.append(float(toks[i][1]))
                i += 1
            i += 1
        elif i < len(toks) and toks[i][0] == "str" and " " not in toks[i][1]:
            args.append(toks[i][1])
            i += 1
        while i < len(toks) and toks[i][0] == "str":
            key = toks[i][1]
            i += 1
            values = []
            if toks[i][0] == "[":
                i += 1
                while toks[i][0] != "]":
                    values.append(toks[i][1])
                    i += 1
                i += 1
            else:
                values.append(toks[i][1])
                i += 1
            params[key] = values
        out.append((name, args, params))
    return out


def floats(params, key, default=None):
    if key not in params:
        if default is None:
            sys.exit(f"missing parameter {key!r}")
        return default
    return [float(v) for v in params[key]]


def write_ply(path, points, indices):
    with open(path, "wb") as f:
        n, t = len(points) // 3, len(indices) // 3
        f.write(
            (
                "ply\nformat binary_little_endian 1.0\n"
                f"element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
                f"element face {t}\nproperty list uchar int vertex_indices\nend_header\n"
            ).encode()
        )
        f.write(struct.pack(f"<{3 * n}f", *points))
        for k in range(t):
            f.write(struct.pack("<B3i", 3, *map(int, indices[3 * k : 3 * k + 3])))


def scene_dict(mi, directives, folder, spp, seed):
    world_to_camera, fov, res, depth = None, None, [1280, 720], 5
    pixel_filter = {"type": "gaussian"}
    materials, current, light, in_attr, shapes = {}, None, None, False, {}
    saved = None
    for name, args, params in directives:
        if name == "Transform":
            world_to_camera = args
        elif name == "Camera":
            if args != ["perspective"]:
                sys.exit(f"Camera {args}: only perspective is read")
            fov = floats(params, "float fov")[0]
        elif name == "Film":
            res = [int(floats(params, "integer xresolution")[0]), int(floats(params, "integer yresolution")[0])]
        elif name == "Sampler":
            spp = spp or int(floats(params, "integer pixelsamples")[0])
        elif name == "Integrator":
            if args != ["path"]:
                sys.exit(f"Integrator {args}: only path is read")
            depth = int(floats(params, "integer maxdepth", [5])[0])
        elif name == "PixelFilter":
            if args not in (["triangle"], ["box"]):
                sys.exit(f"PixelFilter {args}: only triangle and box are read")
            default = [2.0] if args == ["triangle"] else [0.5]
            rx, ry = floats(params, "float xradius", default)[0], floats(params, "float yradius", default)[0]
            if rx != ry:
                sys.exit("PixelFilter: Mitsuba's filters have one radius")
            if args == ["box"] and rx != 0.5:
                sys.exit("PixelFilter box: Mitsuba's box filter has radius 0.5")
            pixel_filter = {"type": "tent", "radius": rx} if args == ["triangle"] else {"type": "box"}
        elif name == "WorldBegin":
            pass
        elif name == "MakeNamedMaterial":
            if params.get("string type") != ["diffuse"]:
                sys.exit(f"MakeNamedMaterial {args}: only diffuse is read")
            materials[args[0]] = floats(params, "rgb reflectance")
        elif name == "NamedMaterial":
            current = args[0]
        elif name == "AttributeBegin":
            in_attr, saved = True, (current, light)
        elif name == "AttributeEnd":
            in_attr = False
            current, light = saved
        elif name == "AreaLightSource":
            if args != ["diffuse"] or not in_attr:
                sys.exit("AreaLightSource: only diffuse, inside AttributeBegin/End, is read")
            light = floats(params, "rgb L")
        elif name == "Shape":
            if args != ["trianglemesh"]:
                sys.exit(f"Shape {args}: only trianglemesh is read")
            ply = os.path.join(folder, f"shape{len(shapes)}.ply")
            write_ply(ply, floats(params, "point3 P"), floats(params, "integer indices"))
            rgb = materials[current]
            shape = {
                "type": "ply",
                "filename": ply,
                "face_normals": True,
                "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}},
            }
            if light is not None:
                shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": light}}
            shapes[f"shape{len(shapes)}"] = shape
        else:
            sys.exit(f"{name}: not part of the subset this script reads")
    if world_to_camera is None or fov is None:
        sys.exit("the scene needs a Transform and a perspective Camera")
    m = world_to_camera
    # pbrt lists the matrix column by column (translation last): transpose into rows.
    rows = [[m[4 * c + r] for c in range(4)] for r in range(4)]
    camera_to_world = mi.ScalarTransform4f(rows).inverse() @ mi.ScalarTransform4f.scale([-1, 1, 1])
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth + 1},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "smaller",
            "to_world": camera_to_world,
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {
                "type": "hdrfilm",
                "width": res[0],
                "height": res[1],
                "pixel_format": "rgb",
                "rfilter": pixel_filter,
            },
        },
    }
    scene.update(shapes)
    return scene, spp


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=0, help="samples per pixel (default: the file's)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--variant", default="scalar_rgb")
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant(a.variant)
    with tempfile.TemporaryDirectory() as folder:
        scene, spp = scene_dict(mi, read_scene(a.scene), folder, a.spp, a.seed)
        image = mi.render(mi.load_dict(scene), spp=spp)
        tmp = a.out + ".part.exr"
        mi.util.write_bitmap(tmp, image, write_async=False)
        os.replace(tmp, a.out)
    print(f"wrote {a.out} (Mitsuba {mi.__version__}, {a.variant}, {spp} spp)")


if __name__ == "__main__":
    main()
