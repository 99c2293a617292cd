# cmake -DOBJDUMP=<avr-objdump> -DELF=<x.elf> -DLST=<x.lst> -P listing.cmake
# Writes the disassembly interleaved with source (avr-objdump -d -S). Done in
# a script because add_custom_command has no portable output redirection.
foreach(v OBJDUMP ELF LST)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "listing.cmake: -D${v}=... is required")
  endif()
endforeach()
execute_process(COMMAND ${OBJDUMP} -d -S ${ELF}
  OUTPUT_FILE ${LST}
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  file(REMOVE ${LST})
  message(FATAL_ERROR "${OBJDUMP} -d -S ${ELF} failed: ${rc}")
endif()
