"""Writes aline-skirt-gerber.dxf: the A-line skirt of aline-skirt.val drafted net (its sew
lines, no seam allowance) in inches, through ezdxf's Gerber AccuMark exporter
(ezdxf.addons.gerber_D6673, ASTM D6673 R12: an empty HEADER, no TABLES).

The geometry is computed here from the same points and curve handles as the Valentina file
(centimetres, Valentina's y axis down, turned y up as its DXF export does); ezdxf is only the
writer. Run: python3 aline-skirt-gerber.py OUT.dxf (ezdxf 1.4, MIT licence, from PyPI).
"""
import math
import sys

import ezdxf
from ezdxf.addons import gerber_D6673

INCH = 2.54  # cm


def p(x, y):
    """A Valentina point (cm, y down) in inches, y up."""
    return (x / INCH, -y / INCH)


def bezier(a, angle1, length1, angle2, length2, b, segments=24):
    """Valentina's simple spline from a to b: handles of the given lengths (cm) at the
    given angles (degrees, counter-clockwise on screen), sampled; a and b in inches."""
    c1 = (a[0] + length1 / INCH * math.cos(math.radians(angle1)), a[1] + length1 / INCH * math.sin(math.radians(angle1)))
    c2 = (b[0] + length2 / INCH * math.cos(math.radians(angle2)), b[1] + length2 / INCH * math.sin(math.radians(angle2)))
    out = []
    for i in range(segments + 1):
        t = i / segments
        u = 1 - t
        out.append(tuple(u**3 * a[k] + 3 * u * u * t * c1[k] + 3 * u * t * t * c2[k] + t**3 * b[k] for k in range(2)))
    return out


def chain(*parts):
    points = []
    for part in parts:
        for q in part:
            if not points or math.dist(points[-1], q) > 1e-9:
                points.append(q)
    if math.dist(points[0], points[-1]) < 1e-9:
        points.pop()
    return points


def notch(block, at, inwards_deg):
    """An ASTM slit notch: a POINT on the outline, 5 mm deep (z), pointing into the piece."""
    block.add_point((at[0], at[1], 0.5 / INCH), dxfattribs={"layer": "4", "angle": inwards_deg})


doc = ezdxf.new("R12")
msp = doc.modelspace()

# Front, cut once: waist, right hip curve, right side, hem, left side, left hip curve.
FWL, FWR, FHR, FHemR, FHemL, FHL = p(15, 0), p(53, 0), p(59.5, 20), p(68, 60), p(0, 60), p(8.5, 20)
front = chain(
    bezier(FWL, 350, 12, 190, 12, FWR),
    bezier(FWR, 300, 7, 102, 7, FHR),
    [FHR, FHemR],
    bezier(FHemR, 192, 20, 348, 20, FHemL),
    [FHemL, FHL],
    bezier(FHL, 78, 7, 240, 7, FWL),
)
# Back half, cut twice (a mirrored pair): centre back waist, waist, side hip curve, side,
# hem, centre back with its zip notch.
BCW, BSW, BSH, BSHem, BCHem, BCN = p(80, 0.5), p(99, 0), p(105.5, 20), p(114, 60), p(80, 61), p(80, 18)
back = chain(
    bezier(BCW, 0, 6, 190, 6, BSW),
    bezier(BSW, 300, 7, 102, 7, BSH),
    [BSH, BSHem],
    bezier(BSHem, 192, 10, 0, 10, BCHem),
    [BCHem, BCN, BCW],
)

for name, outline, quantity, notches, grain_x in [
    ("FRONT", front, 1, [(FHR, 192.0), (FHL, 348.0)], 34),
    ("BACK", back, 2, [(BSH, 192.0), (BCN, 0.0)], 92),
]:
    block = doc.blocks.new(name=name)
    block.add_polyline2d(outline, close=True, dxfattribs={"layer": "1"})
    block.add_line(p(grain_x, 15), p(grain_x, 45), dxfattribs={"layer": "7"})
    for at, angle in notches:
        notch(block, at, angle)
    top = max(q[1] for q in outline)
    for i, text in enumerate([f"Piece Name: {name.title()}", "Size: UK 14", f"Quantity: {quantity}"]):
        block.add_text(text, dxfattribs={"layer": "1", "height": 0.1, "insert": (p(grain_x - 5, 0)[0], top - 1.5 - 0.2 * i)})
    msp.add_blockref(name, (0, 0), dxfattribs={"layer": "1"})

for i, text in enumerate(["Style Name: RosetteAlineSkirt", "Sample Size: UK 14", "Units: ENGLISH"]):
    msp.add_text(text, dxfattribs={"layer": "1", "height": 0.1, "insert": (0, 2 + 0.2 * i)})

gerber_D6673.export_file(doc, sys.argv[1] if len(sys.argv) > 1 else "aline-skirt-gerber.dxf")
