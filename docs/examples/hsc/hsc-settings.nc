; HSC Settings: the example of the cycle documentation (CYCLES-ADC 5.2.4)
T9 D9 ( Tool data )
M6                                ( Tool change )
G00 G17 G90 F2000 M03 S6000      ( Technology data )
G00 Z150                          ( Go to z start position )
G00 X0 Y0                          ( position over the workpiece )

; Finishing Mode
L CYCLE [NAME=SysHscSettings.ecy  \
      @P1 = 4                      \
      ]

; 3D Milling
;...
;...

M30
