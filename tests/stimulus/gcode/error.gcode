; error.gcode: stepdir_test answers error:1 to a command it does not know
E1
G1 X10 ; not a stepdir_test command
X10
