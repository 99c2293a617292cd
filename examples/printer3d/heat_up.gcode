; Heats the hot end of seed 001's printer before a part: the interpolator
; (firmware/printer3d_interp) sends the set point to the heater MCU over TWI
; and waits, printing the heater's status every second, until the heater
; reports the temperature within its tolerance (TEMP_OK). ci/demo streams this
; file and then seed001_part.gcode as one job.
M109 S200               ; hot end to 200 degC and wait
