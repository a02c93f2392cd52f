# The lean-scene report a user reads after a run of obelisk-view on
# tests/data/models/features.gltf with --msaa 4: printed once (not per
# frame), it names each material's PBR variant and the features that variant
# left out -- "plain" (factors only) leaves out the normal texture it lacks,
# "masked" (every texture, mask, vertex colours) leaves out only alpha
# blending and never a feature it has -- and says that the main view has
# MSAA targets; without --msaa it says there are none. A scene whose shadowed
# sun has intensity 0 lists that shadow view as left out (not needed), and
# the views drawn name each shadow view's light (cascades, spot, point).
# Run by ctest: cmake -DBIN=<build>/bin -DSRC=<source> -DOUT=<dir> -P view_lean_report.cmake
foreach(var BIN SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "view_lean_report: -D${var}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT})
set(model ${SRC}/tests/data/models/features.gltf)

function(count_matches text regex out)
  string(REGEX MATCHALL "${regex}" hits "${text}")
  list(LENGTH hits n)
  set(${out} ${n} PARENT_SCOPE)
endfunction()

# Runs obelisk-view on the model with the given options; its stdout into out_var.
function(run_view out_var)
  execute_process(COMMAND ${BIN}/obelisk-view ${model} --quiet --threads 0 ${ARGN}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "obelisk-view ${ARGN} exited ${code}\n${out}\n${err}")
  endif()
  set(${out_var} "${out}" PARENT_SCOPE)
endfunction()

run_view(out --frames 4 --msaa 4)

# plain: factors only -- its left-out list names the normal texture.
set(plain_re "lean: material features.gltf/plain: pbr[^ \n]* \\(left out: [^)\n]*normal texture[^)\n]*\\)")
count_matches("${out}" "${plain_re}" n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one lean line for 'plain' naming 'normal texture' as left out, found ${n}\n${out}")
endif()
# masked: uses every texture, the mask and vertex colours; only blending and
# the glTF extensions features.gltf does not use (texture transforms, a second
# uv set, clearcoat, whose textures are implied) are left out.
string(REGEX MATCH "lean: material features.gltf/masked: [^\n]*" masked "${out}")
if(NOT masked MATCHES "\\(left out: alpha blending, texture transforms, second uv set, clearcoat\\)( \\[[0-9]+ entities\\])?$")
  message(FATAL_ERROR "'masked' should leave out only alpha blending and the unused extensions: '${masked}'\n${out}")
endif()
foreach(used "normal texture" "base colour texture" "alpha mask" "vertex colours")
  string(FIND "${masked}" "${used}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "'masked' uses the ${used} but the report says it was left out: '${masked}'")
  endif()
endforeach()
# Printed once per run, not per frame.
count_matches("${out}" "lean: [0-9]+ shader variants and [0-9]+ pipelines created over 4 frames" n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected the lean report once, found its first line ${n} times\n${out}")
endif()
count_matches("${out}" "lean: views left out:" n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one 'views left out' line, found ${n}\n${out}")
endif()
if(NOT out MATCHES "lean: MSAA targets: view 'main' draws 4x")
  message(FATAL_ERROR "--msaa 4: the report does not say the main view has 4x MSAA targets\n${out}")
endif()

run_view(out1 --frames 2)
if(NOT out1 MATCHES "lean: MSAA targets: none")
  message(FATAL_ERROR "without --msaa the report should say there are no MSAA targets\n${out1}")
endif()
# A shadowed sun of intensity 0 needs no shadow map: the report names that view.
file(WRITE ${OUT}/dark.json [=[
{ "lights": [ { "name": "sun", "type": "directional", "intensity": 0, "shadows": true } ],
  "entities": [ { "name": "box", "geometry": { "generator": "box" } } ] }
]=])
set(model ${OUT}/dark.json)
run_view(dark --frames 2)
if(NOT dark MATCHES "lean: views left out: shadow:sun \\(not needed, 2 frames\\)")
  message(FATAL_ERROR "a sun of intensity 0: the report does not list its shadow view as left out\n${dark}")
endif()
# Every kind of shadow view names its light among the views drawn: the
# sun's cascades, a spot light's map and a point light's cube (issue 28).
function(check_drawn_shadow scene pattern what)
  set(model ${SRC}/tests/golden/scenes/${scene})
  run_view(run --frames 2)
  string(REGEX MATCH "lean: views drawn \\(last frame\\): [^\n]*" drawn "${run}")
  if(NOT drawn MATCHES "${pattern} \\(shadow, [1-9][0-9]* draws\\)")
    message(FATAL_ERROR "${scene}: no drawn ${what} named after its light in '${drawn}'\n${run}")
  endif()
endfunction()
check_drawn_shadow(point_shadow.json "shadow:[^ ,]+" "point-light shadow view")
check_drawn_shadow(cascades.json "shadow:[^ ,:]+:c[0-3]" "cascade")
check_drawn_shadow(spot.json "shadow:[^ ,]+" "spot shadow view")

string(REGEX MATCHALL "lean: [^\n]*" lines "${out}")
list(JOIN lines "\n  " lines)
message(STATUS "lean report:\n  ${lines}")
