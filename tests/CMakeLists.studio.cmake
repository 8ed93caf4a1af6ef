# Studio tests: Qt Test executables with their OWN main (the GL surface format
# must be set before QApplication), one per tests/<tier>/test_*.cpp, labelled
# `ui` or `render`. They need an X display: the suite runs under
#   xvfb-run -a -s "-screen 0 1920x1080x24" ctest ...
# and a test without one fails (it never skips).
set(LC_RENDER_BASELINES ${CMAKE_CURRENT_SOURCE_DIR}/render/baselines)

function(lc_add_studio_tests dir label timeout)
  file(GLOB srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/test_*.cpp)
  foreach(src ${srcs})
    get_filename_component(name ${src} NAME_WE)
    set(target ${dir}_${name})
    add_executable(${target} ${src})
    set_target_properties(${target} PROPERTIES AUTOMOC ON)
    target_link_libraries(${target} PRIVATE lc_ui culling Qt5::Test nlohmann_json::nlohmann_json)
    target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/ui)
    target_compile_definitions(${target} PRIVATE
      LC_ASSETS_DIR="${LIGHTCULL_ASSETS_DIR}" LC_TEST_DATA_DIR="${LC_TEST_DATA_DIR}"
      LC_SOURCE_DIR="${CMAKE_SOURCE_DIR}" LC_CLI_PATH="$<TARGET_FILE:lightcull>"
      LC_RENDER_BASELINES="${LC_RENDER_BASELINES}" LC_RENDER_OUT_DIR="${CMAKE_CURRENT_BINARY_DIR}/render_out"
      LC_STUDIO_PATH="$<TARGET_FILE:lightcull-studio>")
    add_dependencies(${target} lightcull lightcull-studio)
    vtk_module_autoinit(TARGETS ${target} MODULES
      VTK::RenderingOpenGL2 VTK::InteractionStyle VTK::RenderingFreeType VTK::GUISupportQt)
    add_test(NAME ${target} COMMAND ${target})
    set_tests_properties(${target} PROPERTIES LABELS ${label} TIMEOUT ${timeout}
      ENVIRONMENT "QT_QPA_PLATFORM=xcb")
  endforeach()
endfunction()

lc_add_studio_tests(ui ui 300)
# The overlays test reads overlays.vtm back with VTK's own XML reader.
target_link_libraries(ui_test_overlays PRIVATE VTK::IOXML)
# The glTF test reads our files back with VTK's own importer as a second reader.
target_link_libraries(ui_test_gltf_studio PRIVATE VTK::IOImport)
lc_add_studio_tests(render render 300)
