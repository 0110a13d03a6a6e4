; SysPosRotationToPlane, documentation example 1 with @P1 = 3: this machine has no
; kinematic transformation, so only the machining coordinate system is rotated
L CYCLE [NAME=SysPosRotationToPlane.ecy \
    @P1 = 3 \
    @P2 = 50 \
    @P3 = 140 @P4 = 0 @P5 = -80 \
    @P6 = 100 @P7 = 30 @P8 = -25 \
    @P9 = 100 @P10 = 70 @P11 = -25 \
    @P12 = 115 @P13 = 70 @P14 = -50 \
    @P20 = 1 \
]
G01 X10 Y0 Z0 F2000   ( programmed in the rotated system )
#CS OFF ; Deactivate the calculated MCS
M30
