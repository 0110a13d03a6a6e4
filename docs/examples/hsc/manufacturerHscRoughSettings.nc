% manufacturerHscRoughSettings.nc
; the example of the cycle documentation with its lines active
G133 = 180
G134 = 180
#SLOPE[TYPE=HSC]
#HSC ON[SURFACE PATH_DEV=V.G.HSCS.ROUGH.TOLERANCE \
        TRACK_DEV=V.G.HSCS.ROUGH.TOLERANCE]
#FILTER ON [AX_DEV=V.G.HSCS.ROUGH.TOLERANCE]
M17
