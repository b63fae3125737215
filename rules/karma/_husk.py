"""What husk (Karma's renderer) makes of a productName, shared by KA001 and KA002."""

#: productNames husk renders without writing a file: its null raster, and
#: "ip", the interactive MPlay display (Karma Render Settings LOP, Output Picture),
#: with what happens to the image.
NOT_WRITTEN = {
    "husk:null_raster": "husk renders the image but saves nothing",
    "ip": "husk sends the image to an MPlay window instead of a file",
}
