# Build step for one OpenGL shader (run with cmake -P):
#   SOURCE     impl_gl/shaders/<name>.frag (no #version line)
#   INCLUDES   ;-list of core/math files to prepend
#   OUTPUT     the .inc file to write: the full source as a C++ raw string
#   VALIDATOR  glslangValidator, which must accept the full source
get_filename_component(name ${SOURCE} NAME)
set(full "#version 450 core\n")
foreach(include ${INCLUDES})
  file(READ ${include} text)
  string(APPEND full "${text}\n")
endforeach()
file(READ ${SOURCE} body)
string(APPEND full "#line 1\n${body}")
get_filename_component(dir ${OUTPUT} DIRECTORY)
set(checked ${dir}/${name})
file(WRITE ${checked} "${full}")
execute_process(COMMAND ${VALIDATOR} ${checked} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "glslangValidator rejected ${SOURCE}:\n${out}${err}")
endif()
file(WRITE ${OUTPUT} "R\"glsl(${full})glsl\"")
