# hamiltone_bundled_presets(OUTPUT): the rule that writes OUTPUT, the source of the plugin's
# bundledPresets() (plugin/bundled_presets.h), from the presets named in HAMILTONE_PLUGIN_PRESETS,
# in that order (the first is the plugin's default). Rewritten when a preset changes.
set(HAMILTONE_PLUGIN_PRESETS grand-piano paper-c3-string steel-plate gong thunder-sheet
                             small-cymbal grand-piano-strings)

function(hamiltone_bundled_presets output)
  set(files "")
  foreach(preset IN LISTS HAMILTONE_PLUGIN_PRESETS)
    list(APPEND files ${PROJECT_SOURCE_DIR}/presets/${preset}.toml)
  endforeach()
  add_custom_command(
      OUTPUT ${output}
      COMMAND ${CMAKE_COMMAND} "-DPRESETS=${files}" -DOUTPUT=${output}
              -P ${PROJECT_SOURCE_DIR}/cmake/embed_presets.cmake
      DEPENDS ${files} ${PROJECT_SOURCE_DIR}/cmake/embed_presets.cmake
      VERBATIM)
endfunction()
