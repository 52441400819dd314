"""Converts an SVG figure to PNG with the machine's librsvg and cairo (no Python package
needed): python3 docs/scripts/svg-to-png.py IN.svg OUT.png [SCALE]."""
import ctypes
import ctypes.util
import sys


def library(name, soname):
    path = ctypes.util.find_library(name) or soname
    return ctypes.CDLL(path)


def main(source, target, scale=1.0):
    rsvg = library("rsvg-2", "librsvg-2.so.2")
    cairo = library("cairo", "libcairo.so.2")
    rsvg.rsvg_handle_new_from_file.restype = ctypes.c_void_p
    rsvg.rsvg_handle_new_from_file.argtypes = [ctypes.c_char_p, ctypes.c_void_p]
    error = ctypes.c_void_p()
    handle = rsvg.rsvg_handle_new_from_file(source.encode(), ctypes.byref(error))
    if not handle:
        sys.exit(f"svg-to-png: cannot read {source}")

    class Dimensions(ctypes.Structure):
        _fields_ = [("width", ctypes.c_int), ("height", ctypes.c_int),
                    ("em", ctypes.c_double), ("ex", ctypes.c_double)]

    size = Dimensions()
    rsvg.rsvg_handle_get_dimensions.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    rsvg.rsvg_handle_get_dimensions(ctypes.c_void_p(handle), ctypes.byref(size))
    width, height = int(size.width * scale), int(size.height * scale)
    cairo.cairo_image_surface_create.restype = ctypes.c_void_p
    surface = cairo.cairo_image_surface_create(0, width, height)  # CAIRO_FORMAT_ARGB32
    cairo.cairo_create.restype = ctypes.c_void_p
    cairo.cairo_create.argtypes = [ctypes.c_void_p]
    context = cairo.cairo_create(ctypes.c_void_p(surface))
    cairo.cairo_scale.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double]
    cairo.cairo_scale(ctypes.c_void_p(context), scale, scale)
    rsvg.rsvg_handle_render_cairo.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    if not rsvg.rsvg_handle_render_cairo(ctypes.c_void_p(handle), ctypes.c_void_p(context)):
        sys.exit(f"svg-to-png: cannot draw {source}")
    cairo.cairo_surface_write_to_png.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
    if cairo.cairo_surface_write_to_png(ctypes.c_void_p(surface), target.encode()) != 0:
        sys.exit(f"svg-to-png: cannot write {target}")


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4):
        sys.exit("usage: python3 docs/scripts/svg-to-png.py IN.svg OUT.png [SCALE]")
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]) if len(sys.argv) == 4 else 1.0)
