# The OpenGL function loader, generated at build time by glad 2 (python3-glad, docs/architecture.md).
#
# eikonal_add_glad(TARGET) generates include/glad/gl.h and src/gl.c for OpenGL 3.3 core plus a few
# extensions into the build tree and compiles them into the static library TARGET (C, no project
# warnings: generated code is not ours). The loader is initialised at run time with the current
# context's own getProcAddress (OSMesa, EGL or GLFW), so one binary serves every kind of context;
# nothing ever links libGL or calls a gl* symbol directly (docs/architecture.md, "known traps").
#
# `--reproducible` is mandatory: without it glad tries to download the Khronos registry and fails
# offline.

# Extensions the loader knows about. Core 3.3 is the contract; these are used only where the context
# reports them (GLAD_GL_<name> is set by gladLoadGL):
#   KHR_debug / ARB_debug_output   message callback for debug builds (gl/debug.cpp)
#   ARB_texture_storage, ARB_buffer_storage, ARB_copy_image, ARB_clear_texture,
#   ARB_direct_state_access, ARB_compute_shader, ARB_shader_image_load_store,
#   ARB_shader_storage_buffer_object, ARB_gpu_shader5, ARB_clip_control,
#   EXT_texture_filter_anisotropic, ARB_get_program_binary, ARB_parallel_shader_compile
#                                  optional fast paths for the programs (Mesa 22 offers all of them)
set(EIKONAL_GLAD_EXTENSIONS
    GL_KHR_debug
    GL_ARB_debug_output
    GL_ARB_texture_storage
    GL_ARB_buffer_storage
    GL_ARB_copy_image
    GL_ARB_clear_texture
    GL_ARB_direct_state_access
    GL_ARB_compute_shader
    GL_ARB_shader_image_load_store
    GL_ARB_shader_storage_buffer_object
    GL_ARB_gpu_shader5
    GL_ARB_clip_control
    GL_EXT_texture_filter_anisotropic
    GL_ARB_get_program_binary
    GL_ARB_parallel_shader_compile)

function(eikonal_add_glad target)
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/glad)
  list(JOIN EIKONAL_GLAD_EXTENSIONS "," extensions)
  set(outputs ${out_dir}/include/glad/gl.h ${out_dir}/include/KHR/khrplatform.h ${out_dir}/src/gl.c)
  add_custom_command(
    OUTPUT ${outputs}
    COMMAND ${CMAKE_COMMAND} -E remove_directory ${out_dir}
    COMMAND ${GLAD_EXECUTABLE} --quiet --reproducible --api gl:core=3.3 --extensions ${extensions}
            --out-path ${out_dir} c
    DEPENDS ${GLAD_EXECUTABLE} ${CMAKE_CURRENT_FUNCTION_LIST_FILE}
    COMMENT "Generating the OpenGL 3.3 core loader with glad"
    VERBATIM)
  add_library(${target} STATIC ${out_dir}/src/gl.c ${out_dir}/include/glad/gl.h)
  target_include_directories(${target} SYSTEM PUBLIC ${out_dir}/include)
  set_target_properties(${target} PROPERTIES LINKER_LANGUAGE C POSITION_INDEPENDENT_CODE ON)
endfunction()
