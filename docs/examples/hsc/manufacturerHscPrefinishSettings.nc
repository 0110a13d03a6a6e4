% manufacturerHscPrefinishSettings.nc
; the example of the cycle documentation with its lines active
G133 = 150
G134 = 150
#SLOPE[TYPE=HSC]
#HSC ON[SURFACE PATH_DEV=V.G.HSCS.PREFINISH.TOLERANCE \
        TRACK_DEV=V.G.HSCS.PREFINISH.TOLERANCE]
#FILTER ON [AX_DEV=V.G.HSCS.PREFINISH.TOLERANCE]
M17
