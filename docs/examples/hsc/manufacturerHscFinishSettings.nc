% manufacturerHscFinishSettings.nc
; the example of the cycle documentation with its lines active
G133 = 80
G134 = 80
#SLOPE[TYPE=HSC]
#HSC ON[SURFACE PATH_DEV=V.G.HSCS.FINISH.TOLERANCE \
        TRACK_DEV=V.G.HSCS.FINISH.TOLERANCE]
#FILTER ON [AX_DEV=V.G.HSCS.FINISH.TOLERANCE]
M17
