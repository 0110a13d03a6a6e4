; Five axes (make run MACHINE=five-axis-ac): the tool tip stays on the programmed
; line while the table turns; then the tool is tilted onto an inclined plane
G90 G00 X0 Y0 Z50 A0 C0
#TRAFO ON
G01 X40 C90 F3000              ; the tip 40 mm along the workpiece's X, the table turns 90
L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=1 @P2=20 @P3=40 @P4=0 @P5=0 @P15=30]
G01 X10 Y0 Z0 F6000            ; in the tilted plane, the tool perpendicular to it
#CS OFF
#TRAFO OFF
M30
