# Houdini Python SOP: the strands of a vdbhair strands.vdb as open polylines, root first.
#
# Network: File SOP (strands.vdb) -> Convert VDB Points -> Python SOP with this code.
# Convert VDB Points unpacks the points in spatial order with their `strand` and `vertex`
# attributes (int32 from vdbhair; Houdini's own points may hold them as floats); this orders the
# points by (strand, vertex) and builds one polyline per strand, in strand order. The points keep
# every other attribute (Cd, width, Alpha, the group `root`).
node = hou.pwd()
geo = node.geometry()


def whole_numbers(name):
    attrib = geo.findPointAttrib(name)
    if attrib is None:
        raise hou.NodeError("no point attribute '%s': unpack a vdbhair strands.vdb with Convert VDB Points first" % name)
    if attrib.dataType() == hou.attribData.Int:
        return geo.pointIntAttribValues(name)
    return [int(round(v)) for v in geo.pointFloatAttribValues(name)]


strand = whole_numbers("strand")
vertex = whole_numbers("vertex")
points = geo.points()
curves = []
previous = None
for i in sorted(range(len(points)), key=lambda i: (strand[i], vertex[i])):
    if strand[i] != previous:
        curves.append([])
        previous = strand[i]
    curves[-1].append(points[i])
geo.createPolygons(curves, False)  # is_closed=False: polylines
