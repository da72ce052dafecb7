# SDFCage — the VTK faces of the project, included by the top-level CMakeLists.txt:
#   * the VTK module SDFCage::Filters (library SDFCageFilters, Filters/vtk.module),
#   * its Python wrapping as the package `sdfcage`,
#   * the ParaView plugin SDFCage (Plugin/), with SDFCAGE_USE_PARAVIEW=ON (the default),
#   * the command-line example (Examples/CLI), when present.
#
# SDFCAGE_USE_PARAVIEW=ON  builds against ParaView 5.11 and the VTK 9.2 it bundles (the
#                          *-pv5.11 libraries; `import vtk` in /usr/bin/python3 is this VTK).
# SDFCAGE_USE_PARAVIEW=OFF builds the same module against a plain VTK >= 9.1 (e.g. Debian's
#                          libvtk9-dev); no plugin, Python wrapping when that VTK has it.
# Never mix the two VTKs in one build or one process.
#
# Build-tree layout (use these without installing):
#   <build>/lib/libSDFCageFilters.so                       the VTK module
#   <build>/lib/python3/dist-packages/sdfcage/             PYTHONPATH=<build>/lib/python3/dist-packages
#   <build>/lib/paraview-5.11/plugins/SDFCage/SDFCage.so   PV_PLUGIN_PATH=<build>/lib/paraview-5.11/plugins/SDFCage
#                                                          or LoadPlugin("<that>/SDFCage.so", remote=False, ns=globals())
#
# Variables set here for the rest of the build (CLI, tests):
#   SDFCAGE_VTK_FOUND              TRUE once SDFCage::Filters exists
#   SDFCAGE_VTK_FLAVOR             "ParaView" or "VTK"
#   SDFCAGE_VTK_MODULES            modules built here (SDFCage::Filters)
#   SDFCAGE_VTK_IO_MODULES         VTK::IOPLY;VTK::IOGeometry;VTK::IOXML;VTK::IOLegacy;VTK::IOImage
#                                  (those found; all are found with ParaView 5.11 on Debian 12)
#   SDFCAGE_VTK_RENDERING_FOUND    TRUE when every module of SDFCAGE_VTK_RENDERING_MODULES was found
#   SDFCAGE_VTK_RENDERING_MODULES  VTK::RenderingCore;VTK::RenderingOpenGL2;VTK::InteractionStyle;
#                                  VTK::RenderingFreeType;VTK::RenderingUI (empty when not found:
#                                  RenderingOpenGL2 needs GLEW's headers, i.e. libglew-dev)
#   SDFCAGE_VTK_TEST_MODULES       VTK::FiltersCore;VTK::FiltersSources;VTK::FiltersGeneral
#   SDFCAGE_PYTHON_WRAPPED         TRUE when the `sdfcage` Python package is built
#   SDFCAGE_PYTHON_EXECUTABLE      the interpreter that can import it (/usr/bin/python3 here)
#   SDFCAGE_PYTHONPATH             <build>/lib/python3/dist-packages
#   SDFCAGE_PLUGIN_DIR             <build>/lib/paraview-5.11/plugins/SDFCage (ParaView only)
#   SDFCAGE_PLUGIN_FILE            $<TARGET_FILE:SDFCage> as a plain path (ParaView only)
#   SDFCAGE_PVBATCH, SDFCAGE_PVPYTHON  ParaView's executables (ParaView only, may be NOTFOUND)
# An executable using VTK rendering must call
#   vtk_module_autoinit(TARGETS <target> MODULES ${SDFCAGE_VTK_RENDERING_MODULES})
# so that the OpenGL2 factory overrides are registered.

include(GNUInstallDirs)

set(SDFCAGE_VTK_FOUND FALSE)
set(SDFCAGE_VTK_MODULES)
set(SDFCAGE_VTK_IO_MODULES)
set(SDFCAGE_VTK_RENDERING_MODULES)
set(SDFCAGE_VTK_RENDERING_FOUND FALSE)
set(SDFCAGE_PYTHON_WRAPPED FALSE)
set(SDFCAGE_PYTHONPATH)
set(SDFCAGE_PLUGIN_DIR)
set(SDFCAGE_PLUGIN_FILE)

set(SDFCAGE_PYTHON_DESTINATION "lib/python3/dist-packages" CACHE STRING
  "Where the `sdfcage` Python package goes, relative to the build tree and the install prefix")
mark_as_advanced(SDFCAGE_PYTHON_DESTINATION)

# What the module itself needs, what the tests need, what the CLI may use.
set(_sdfcage_vtk_module_components
  CommonCore CommonDataModel CommonExecutionModel CommonMisc IOCore ParallelCore)
set(_sdfcage_vtk_test_components
  FiltersCore FiltersSources FiltersGeneral)
set(_sdfcage_vtk_io_components
  IOPLY IOGeometry IOXML IOLegacy IOImage)
set(_sdfcage_vtk_rendering_components
  RenderingCore RenderingOpenGL2 InteractionStyle RenderingFreeType RenderingUI)

# Shared libraries for the module, the Python module and the plugin (a static plugin cannot be
# loaded at run time); restored at the end so other parts of the build are not affected.
set(_sdfcage_saved_build_shared_libs "${BUILD_SHARED_LIBS}")
set(BUILD_SHARED_LIBS ON)

# --- find ParaView / VTK -----------------------------------------------------------------------
if (SDFCAGE_USE_PARAVIEW)
  # Asking for components keeps ParaView from finding (and requiring) Qt, GDAL, FFmpeg, ...
  find_package(ParaView 5.11 REQUIRED COMPONENTS RemotingCore RemotingServerManager)
  if (NOT PARAVIEW_USE_PYTHON)
    message(FATAL_ERROR "SDFCage needs a ParaView with Python (python3-paraview).")
  endif ()
  # The VTK bundled with ParaView: import the modules we need (their own dependencies, e.g.
  # GLEW for rendering, are only searched for the components asked for).
  find_package(Python3 3.6 REQUIRED COMPONENTS Interpreter Development)
  find_package(VTK REQUIRED
    COMPONENTS ${_sdfcage_vtk_module_components} ${_sdfcage_vtk_test_components}
      ${_sdfcage_vtk_io_components} Python WrappingPythonCore
    OPTIONAL_COMPONENTS ${_sdfcage_vtk_rendering_components}
    PATHS "${ParaView_DIR}/vtk"
    NO_DEFAULT_PATH)
  set(SDFCAGE_VTK_FLAVOR "ParaView")
  set(_sdfcage_wrap_python ON)
  message(STATUS "SDFCage: ParaView ${ParaView_VERSION} (VTK ${VTK_VERSION}) from ${ParaView_DIR}")
else ()
  find_package(VTK 9.1 REQUIRED
    COMPONENTS ${_sdfcage_vtk_module_components} ${_sdfcage_vtk_test_components}
    OPTIONAL_COMPONENTS ${_sdfcage_vtk_io_components} ${_sdfcage_vtk_rendering_components}
      Python WrappingPythonCore)
  set(SDFCAGE_VTK_FLAVOR "VTK")
  set(_sdfcage_wrap_python OFF)
  if (VTK_WRAP_PYTHON AND TARGET VTK::WrappingPythonCore)
    set(_sdfcage_wrap_python ON)
  endif ()
  option(SDFCAGE_WRAP_PYTHON "Build the `sdfcage` Python package (plain-VTK build)" ${_sdfcage_wrap_python})
  set(_sdfcage_wrap_python ${SDFCAGE_WRAP_PYTHON})
  if (_sdfcage_wrap_python)
    find_package(Python3 3.6 REQUIRED COMPONENTS Interpreter Development)
  endif ()
  message(STATUS "SDFCage: VTK ${VTK_VERSION} from ${VTK_DIR} (no ParaView plugin)")
endif ()

# VTK marks a component found even when a third-party target it links (e.g. GLEW::GLEW, whose
# headers come with libglew-dev) is missing; linking it then fails at generate time. So a module
# counts as usable only if every namespaced target in its interface link closure exists.
function (_sdfcage_vtk_usable out module)
  set(_usable TRUE)
  set(_visited)
  set(_pending "${module}")
  while (_pending)
    list(POP_FRONT _pending _item)
    string(REGEX REPLACE "^\\$<LINK_ONLY:([^>]*)>$" "\\1" _item "${_item}")
    if (_item IN_LIST _visited OR NOT _item MATCHES "::" OR _item MATCHES "^\\$<")
      continue ()
    endif ()
    list(APPEND _visited "${_item}")
    if (NOT TARGET "${_item}")
      set(_usable FALSE)
      break ()
    endif ()
    get_target_property(_links "${_item}" INTERFACE_LINK_LIBRARIES)
    if (_links)
      list(APPEND _pending ${_links})
    endif ()
  endwhile ()
  set("${out}" "${_usable}" PARENT_SCOPE)
endfunction ()

foreach (_sdfcage_component IN LISTS _sdfcage_vtk_io_components)
  _sdfcage_vtk_usable(_sdfcage_usable "VTK::${_sdfcage_component}")
  if ((VTK_${_sdfcage_component}_FOUND OR SDFCAGE_USE_PARAVIEW) AND _sdfcage_usable)
    list(APPEND SDFCAGE_VTK_IO_MODULES "VTK::${_sdfcage_component}")
  endif ()
endforeach ()
set(SDFCAGE_VTK_RENDERING_FOUND TRUE)
foreach (_sdfcage_component IN LISTS _sdfcage_vtk_rendering_components)
  _sdfcage_vtk_usable(_sdfcage_usable "VTK::${_sdfcage_component}")
  if (NOT VTK_${_sdfcage_component}_FOUND OR NOT _sdfcage_usable)
    set(SDFCAGE_VTK_RENDERING_FOUND FALSE)
  endif ()
endforeach ()
if (SDFCAGE_VTK_RENDERING_FOUND)
  foreach (_sdfcage_component IN LISTS _sdfcage_vtk_rendering_components)
    list(APPEND SDFCAGE_VTK_RENDERING_MODULES "VTK::${_sdfcage_component}")
  endforeach ()
else ()
  message(STATUS "SDFCage: VTK rendering modules not usable from C++ (RenderingOpenGL2 needs "
    "GLEW headers: apt-get install libglew-dev); SDFCAGE_VTK_RENDERING_FOUND=FALSE")
endif ()
set(SDFCAGE_VTK_TEST_MODULES)
foreach (_sdfcage_component IN LISTS _sdfcage_vtk_test_components)
  list(APPEND SDFCAGE_VTK_TEST_MODULES "VTK::${_sdfcage_component}")
endforeach ()

# --- the VTK module ---------------------------------------------------------------------------
vtk_module_scan(
  MODULE_FILES            "${CMAKE_CURRENT_SOURCE_DIR}/Filters/vtk.module"
  REQUEST_MODULES         SDFCage::Filters
  PROVIDES_MODULES        SDFCAGE_VTK_MODULES
  HIDE_MODULES_FROM_CACHE ON)
vtk_module_build(
  MODULES             ${SDFCAGE_VTK_MODULES}
  PACKAGE             SDFCage
  INSTALL_EXPORT      SDFCage
  VERSION             "${PROJECT_VERSION}"
  SOVERSION           "${PROJECT_VERSION_MAJOR}"
  ENABLE_WRAPPING     ON
  ARCHIVE_DESTINATION "lib"
  LIBRARY_DESTINATION "lib"
  RUNTIME_DESTINATION "bin"
  HEADERS_DESTINATION "include/SDFCage"
  CMAKE_DESTINATION   "lib/cmake/SDFCage")
set(SDFCAGE_VTK_FOUND TRUE)

# --- Python package `sdfcage` ------------------------------------------------------------------
if (_sdfcage_wrap_python)
  vtk_module_wrap_python(
    MODULES             ${SDFCAGE_VTK_MODULES}
    TARGET              SDFCage::Python
    PYTHON_PACKAGE      sdfcage
    MODULE_DESTINATION  "${SDFCAGE_PYTHON_DESTINATION}"
    LIBRARY_DESTINATION "lib"
    CMAKE_DESTINATION   "lib/cmake/SDFCage"
    SOABI               "${Python3_SOABI}"
    INSTALL_HEADERS     OFF
    BUILD_STATIC        OFF)
  # The package's __init__: import the VTK modules our classes derive from first, so that their
  # Python types exist, then expose the wrapped classes as sdfcage.<class>.
  set(SDFCAGE_PYTHONPATH "${CMAKE_BINARY_DIR}/${SDFCAGE_PYTHON_DESTINATION}")
  file(WRITE "${SDFCAGE_PYTHONPATH}/sdfcage/__init__.py"
    "\"\"\"SDFCage: cages from an SDF envelope (VTK filters). Import vtk before or after; both work.\"\"\"\n"
    "from vtkmodules import vtkCommonCore, vtkCommonDataModel, vtkCommonExecutionModel, vtkIOCore\n"
    "from .SDFCageFilters import *  # noqa: F401,F403\n"
    "__version__ = \"${PROJECT_VERSION}\"\n")
  install(
    FILES       "${SDFCAGE_PYTHONPATH}/sdfcage/__init__.py"
    DESTINATION "${SDFCAGE_PYTHON_DESTINATION}/sdfcage"
    COMPONENT   python)
  set(SDFCAGE_PYTHON_WRAPPED TRUE)
  set(SDFCAGE_PYTHON_EXECUTABLE "${Python3_EXECUTABLE}")
endif ()

# --- ParaView plugin ---------------------------------------------------------------------------
if (SDFCAGE_USE_PARAVIEW)
  paraview_plugin_scan(
    PLUGIN_FILES           "${CMAKE_CURRENT_SOURCE_DIR}/Plugin/paraview.plugin"
    PROVIDES_PLUGINS       _sdfcage_plugins
    ENABLE_BY_DEFAULT      ON
    HIDE_PLUGINS_FROM_CACHE ON)
  paraview_plugin_build(
    PLUGINS              ${_sdfcage_plugins}
    RUNTIME_DESTINATION  "bin"
    LIBRARY_DESTINATION  "lib"
    LIBRARY_SUBDIRECTORY "${PARAVIEW_PLUGIN_SUBDIR}"
    INSTALL_HEADERS      OFF
    ADD_INSTALL_RPATHS   ON
    DISABLE_XML_DOCUMENTATION ON)
  set(SDFCAGE_PLUGIN_DIR "${CMAKE_BINARY_DIR}/lib/${PARAVIEW_PLUGIN_SUBDIR}/SDFCage")
  set(SDFCAGE_PLUGIN_FILE "${SDFCAGE_PLUGIN_DIR}/SDFCage${CMAKE_SHARED_MODULE_SUFFIX}")
  find_program(SDFCAGE_PVBATCH NAMES pvbatch HINTS "${ParaView_PREFIX_PATH}/bin")
  find_program(SDFCAGE_PVPYTHON NAMES pvpython HINTS "${ParaView_PREFIX_PATH}/bin")
  mark_as_advanced(SDFCAGE_PVBATCH SDFCAGE_PVPYTHON)
endif ()

set(BUILD_SHARED_LIBS "${_sdfcage_saved_build_shared_libs}")

message(STATUS "SDFCage: Python package ${SDFCAGE_PYTHON_WRAPPED} (PYTHONPATH=${SDFCAGE_PYTHONPATH}), "
  "plugin ${SDFCAGE_PLUGIN_DIR}, IO modules ${SDFCAGE_VTK_IO_MODULES}, "
  "rendering ${SDFCAGE_VTK_RENDERING_FOUND}")

# --- command-line example (owned by the CLI developer) ------------------------------------------
# >>> SDFCage CLI hook: keep this line; Examples/CLI links SDFCage::Filters and SDFCAGE_VTK_*.
if (EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/Examples/CLI/CMakeLists.txt)
  add_subdirectory(Examples/CLI)
endif ()
# <<< SDFCage CLI hook
