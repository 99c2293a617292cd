# Unity batches that are the same bytes in every clone.
#
# CMake's own unity sources (CMAKE_UNITY_BUILD) include each .cpp by its
# absolute path, so a clone in another folder compiles other sources and
# ccache (ci/env) shares nothing between clones: not with the install
# recipe's fresh clone (ci/recipe-test), not with a CI runner's checkout.
# avrbench_unity(TARGET) makes the target's batches itself, each .cpp
# included by its path relative to the batch file, and turns CMake's
# batching off for that target. A build folder at the same place in any
# clone (build/, build-release/) then compiles the same sources.
# Sources with compile definitions or options of their own stay single, as
# CMake's unity build leaves them (boards/BoardFile.cpp).
function(avrbench_unity target)
  if(NOT CMAKE_UNITY_BUILD)
    return()
  endif()
  get_target_property(sources ${target} SOURCES)
  get_target_property(target_source_dir ${target} SOURCE_DIR)
  set(batch_dir ${CMAKE_CURRENT_BINARY_DIR}/avrbench_unity)
  set(batched "")  # absolute paths, in the target's order
  set(kept "")     # the target's other sources, as it named them
  foreach(source IN LISTS sources)
    cmake_path(ABSOLUTE_PATH source BASE_DIRECTORY ${target_source_dir} OUTPUT_VARIABLE path)
    get_source_file_property(definitions ${path} COMPILE_DEFINITIONS)
    get_source_file_property(options ${path} COMPILE_OPTIONS)
    if(path MATCHES "\\.cpp$" AND NOT definitions AND NOT options)
      list(APPEND batched ${path})
    else()
      list(APPEND kept ${source})
    endif()
  endforeach()
  set(batch_files "")
  set(content "")
  set(in_batch 0)
  set(batch 0)
  list(LENGTH batched remaining)
  foreach(path IN LISTS batched)
    file(RELATIVE_PATH relative ${batch_dir} ${path})
    string(APPEND content "#include \"${relative}\"\n")
    math(EXPR in_batch "${in_batch} + 1")
    math(EXPR remaining "${remaining} - 1")
    if(in_batch EQUAL CMAKE_UNITY_BUILD_BATCH_SIZE OR remaining EQUAL 0)
      set(batch_file ${batch_dir}/${target}_${batch}.cpp)
      set(previous "")
      if(EXISTS ${batch_file})
        file(READ ${batch_file} previous)
      endif()
      if(NOT previous STREQUAL content)  # rewritten only when it changes: no needless recompile
        file(WRITE ${batch_file} "${content}")
      endif()
      list(APPEND batch_files ${batch_file})
      set(content "")
      set(in_batch 0)
      math(EXPR batch "${batch} + 1")
    endif()
  endforeach()
  # The batched files leave the target's sources (not marked header-only:
  # that property is the directory's, and another target may compile the
  # same file on its own, as the AFL++ mutator does stimulus/GcodeMutator.cpp).
  set_property(TARGET ${target} PROPERTY SOURCES ${kept} ${batch_files})
  set_target_properties(${target} PROPERTIES UNITY_BUILD OFF)
endfunction()
