# Every example scene, to its end (docs/validation.md, "Every example scene, to its end"): each
# examples/scenes/*.json (found when CMake runs, so a new scene is covered without a line here)
# through `motes run SCENE --backend B --format none` on openmp, vulkan (lavapipe in CI, under the
# validation layer where the build's tests use it) and cuda (reported skipped without a CUDA
# device), one test each so that ctest -j runs them side by side: ExampleScene.<scene>.<backend>.
# scene_to_end_test.sh fails a run on a non-zero exit, any warning line, fewer steps than asked,
# and a summary guard line that is missing or does not say `no warning`.
#
# Every run goes to the scene's own settings.duration ("full") but those listed shorter below,
# which stop where what the scene is about (the landing, the impact, the fold) is over: lavapipe
# runs the force-law scenes 6 to 60 times slower than openmp (CI: 2 cores, a few minutes for all
# of these), and scripts/gpu/run-suite.sh scenes runs every scene to its end on CUDA and Vulkan.
# Times: from the CSV frames of full openmp runs (the largest particle speed and the kinetic
# energy per frame). cpu: CPU seconds of one run on the 2-core development machine (user + sys,
# under a load of 8 to 13 from other work, so somewhat high); it orders the runs (COST), longest
# first, so that none starts last and keeps one core idle. A scene not listed runs full, cost 0.
set(motes_scene_runs
  # scene | backend | CI duration (s) | scene's duration (s) | cpu | why
  "bunny|openmp|full|1.5|10|"
  "bunny|vulkan|0.3|1.5|34|lands at 0.08 s and rocks, fastest again at 0.28 s, at rest by 1.2 s"
  "cloth|openmp|full|1.5|56|"
  "cloth|vulkan|0.3|1.5|142|meets the bunnies at 0.22 s, fastest at 0.24 s, whips until 0.32 s"
  "dice|openmp|full|1.5|12|"
  "dice|vulkan|0.3|1.5|26|land from 0.08 s, fastest at 0.12 s, tumble until 0.5 s"
  "dominoes|openmp|full|2.5|3|"
  "fluid_cloth|openmp|full|2.0|9|"
  "fluid_cloth|vulkan|0.6|2.0|10|the stream reaches the cloth at 0.11 s and pours into it until 0.55 s, sagging it"
  "fluid_dam_break|openmp|full|2.0|30|"
  "fluid_dam_break|vulkan|0.5|2.0|28|the surge reaches the blocks at 0.15 s and the far wall at 0.3 s, climbs it and falls back by 0.5 s, fastest at 0.2 s"
  "fluid_floating|openmp|full|2.0|20|"
  "fluid_floating|vulkan|0.4|2.0|16|the cubes land in the water at 0.06 s and bob until 0.4 s"
  "fluid_mixed|openmp|full|1.5|5|"
  "fluid_mixed|vulkan|0.6|1.5|12|the bodies land in the hammock by 0.2 s, the water at 0.35 s"
  "fluid_wave|openmp|full|2.0|28|"
  "fluid_wave|vulkan|0.5|2.0|22|the surge hits the stack at 0.12 s and the soft cube at 0.2 s, fastest at 0.2 s"
  "dominoes|vulkan|full|2.5|41|"
  "impulse_dominoes|openmp|full|2.5|11|"
  "impulse_dominoes|vulkan|full|2.5|48|"
  "mixed|openmp|full|1.2|49|"
  "mixed|vulkan|0.22|1.2|104|a die lands on the floor at 0.14 s, a die and the jelly in the hammock at 0.17 and 0.19 s"
  "position_dominoes|openmp|full|2.5|1|"
  "position_dominoes|vulkan|full|2.5|7|"
  "position_dice|openmp|full|1.5|2|"
  "position_dice|vulkan|full|1.5|21|"
  "pendulum|openmp|full|2.0|6|"
  "pendulum|vulkan|0.3|2.0|27|the bobs through the bottom of their first swing, fastest at 0.25 to 0.3 s"
  "rope|openmp|full|2.0|3|"
  "rope|vulkan|0.3|2.0|19|the boxes land on the bridge at 0.15 to 0.2 s, the swinging rope fastest at 0.2 s"
  "soft|openmp|full|1.0|15|"
  "soft|vulkan|0.2|1.0|49|the three cubes land on the floor and on each other by 0.18 s"
  "tablecloth|openmp|full|1.0|48|"
  "tablecloth|vulkan|0.2|1.0|101|meets the table at 0.14 s, its rim fastest at 0.16 s and folding"
)
# CUDA runs every scene to its end (on the GPU machine; elsewhere reported skipped).

# The sanitizer build (MOTES_SANITIZE) runs the same tests for their first 1,000 steps (about
# 80 CPU seconds for all of them): that stage looks for memory errors and undefined behaviour
# along the run's code paths (loading, the device, the step, the guard, the summary); the physics
# to the end was checked in the first stage, and the kernels' contact paths are in the unit and
# conformance tests there.
set(motes_scene_sanitize_run steps:1000)
# Position contacts' steps are frames of 8 to 10 substeps of 21 kernel calls (about 200 a step,
# where an impulse step makes about 50): their first 40 frames (0.67 s), which the stage's time
# asks for (position_dominoes.json's 150 frames took up to 45 s a backend under the sanitizers).
set(motes_scene_sanitize_position_run steps:40)
# Scenes with water: their first 8 frames (their fluid kernels run from the first substep; the
# dam break's 8 frames took about 10 s a backend without the sanitizers on 2 cores).
set(motes_scene_sanitize_fluid_run steps:8)

# Every entry has its fields (no ';' in the why) and names a scene that exists and a backend.
foreach(entry IN LISTS motes_scene_runs)
  string(REPLACE "|" ";" fields "${entry}")
  list(LENGTH fields n)
  if(n LESS 5 OR n GREATER 6)
    message(FATAL_ERROR "tests/scenes/scenes.cmake: an entry is not scene|backend|CI duration|"
                        "duration|cpu|why: ${entry}")
  endif()
  list(GET fields 0 s)
  list(GET fields 1 b)
  if(NOT EXISTS ${PROJECT_SOURCE_DIR}/examples/scenes/${s}.json OR NOT b MATCHES "^(openmp|vulkan|cuda)$")
    message(FATAL_ERROR "tests/scenes/scenes.cmake lists ${s} on ${b}: no such scene or backend")
  endif()
endforeach()

file(GLOB motes_scenes CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/examples/scenes/*.json)
set(motes_scene_backends openmp)
if(MOTES_VULKAN)
  list(APPEND motes_scene_backends vulkan)
endif()
if(MOTES_CUDA)
  list(APPEND motes_scene_backends cuda)
endif()
foreach(scene IN LISTS motes_scenes)
  get_filename_component(name ${scene} NAME_WE)
  file(READ ${scene} text)
  string(JSON scene_duration ERROR_VARIABLE no_duration GET "${text}" settings duration)
  if(no_duration)
    message(FATAL_ERROR "${scene}: no settings.duration, which ExampleScene.${name}.* run to")
  endif()
  foreach(backend IN LISTS motes_scene_backends)
    set(seconds "full")
    set(why "")
    set(cost 0)
    foreach(entry IN LISTS motes_scene_runs)
      string(REPLACE "|" ";" fields "${entry}")
      list(GET fields 0 s)
      list(GET fields 1 b)
      if(s STREQUAL name AND b STREQUAL backend)
        list(GET fields 2 seconds)
        list(GET fields 3 listed_full)
        list(GET fields 4 cost)
        list(LENGTH fields n)
        if(n GREATER 5)
          list(GET fields 5 why)
        endif()
        # A scene whose duration changed is measured again before its shortening is trusted.
        if(NOT listed_full EQUAL scene_duration)
          message(FATAL_ERROR "tests/scenes/scenes.cmake lists ${name} as ${listed_full} s long; "
                              "${scene} says ${scene_duration} s: measure it again and update the entry")
        endif()
        if(NOT seconds STREQUAL "full" AND NOT seconds LESS scene_duration)
          message(FATAL_ERROR "tests/scenes/scenes.cmake shortens ${name} on ${backend} to "
                              "${seconds} s, not less than its ${scene_duration} s")
        endif()
      endif()
    endforeach()
    if(MOTES_SANITIZE)
      string(JSON contact_model ERROR_VARIABLE no_model GET "${text}" settings contact_model)
      if(name MATCHES "^fluid_")
        set(seconds ${motes_scene_sanitize_fluid_run})
      elseif(NOT no_model AND contact_model STREQUAL "position")
        set(seconds ${motes_scene_sanitize_position_run})
      else()
        set(seconds ${motes_scene_sanitize_run})
      endif()
      set(why "the sanitizer build, tests/scenes/scenes.cmake")
    endif()
    set(test ExampleScene.${name}.${backend})
    add_test(NAME ${test}
      COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/scenes/scene_to_end_test.sh
              $<TARGET_FILE:motes_cli> ${scene} ${backend} ${seconds} ${scene_duration} "${why}"
              ${CMAKE_CURRENT_BINARY_DIR}/scenes/${name}-${backend}.log)
    set_tests_properties(${test} PROPERTIES LABELS scenes SKIP_RETURN_CODE 77 COST ${cost}
      ENVIRONMENT "MOTES_VULKAN_VALIDATION=${motes_test_validation}")
  endforeach()
endforeach()
# The test's own test: a run that warns, a guard line counting warnings, a short run... must fail.
add_test(NAME ExampleScene.TestFailsOnWarnings
  COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/scenes/scene_to_end_selftest.sh
          $<TARGET_FILE:motes_cli> ${CMAKE_CURRENT_BINARY_DIR}/scenes/selftest)
set_tests_properties(ExampleScene.TestFailsOnWarnings PROPERTIES LABELS scenes)
