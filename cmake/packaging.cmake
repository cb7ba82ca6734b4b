# Installation and the Debian package (packaging/README.md): `cmake --install build` puts daq,
# its manual pages, its bash completion, the udev rules and the service's unit and
# configuration in place; `scripts/package` (cpack -G DEB) makes caldaq_VERSION_ARCH.deb and
# python3-caldaq_VERSION_ARCH.deb of the same files.
include(GNUInstallDirs)

# The manual pages and completion come from daq's own command tree (daq man-pages, daq
# completion), so they say what --help says; made with the executable.
set(caldaq_doc_dir ${CMAKE_BINARY_DIR}/packaging)
add_custom_command(
  OUTPUT ${caldaq_doc_dir}/man.stamp ${caldaq_doc_dir}/daq.bash
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${caldaq_doc_dir}/man
  COMMAND $<TARGET_FILE:daq> man-pages ${caldaq_doc_dir}/man
  COMMAND gzip -9n -f ${caldaq_doc_dir}/man/*.1
  COMMAND $<TARGET_FILE:daq> completion bash > ${caldaq_doc_dir}/daq.bash
  COMMAND ${CMAKE_COMMAND} -E touch ${caldaq_doc_dir}/man.stamp
  DEPENDS daq
  COMMENT "Manual pages and bash completion from daq's command tree")
add_custom_target(daq_docs ALL DEPENDS ${caldaq_doc_dir}/man.stamp ${caldaq_doc_dir}/daq.bash)

install(TARGETS daq RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT daq)
install(DIRECTORY ${caldaq_doc_dir}/man/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT daq
        FILES_MATCHING PATTERN "*.1.gz")
install(FILES ${caldaq_doc_dir}/daq.bash DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions
        RENAME daq COMPONENT daq)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT daq)
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs COMPONENT daq)
# Where Debian 12's udev and systemd read a package's rules and units (not /usr/lib: the
# merged-/usr aliasing rules of bookworm's dpkg).
install(FILES udev/60-caldaq.rules udev/61-caldaq-plugdev.rules DESTINATION /lib/udev/rules.d
        COMPONENT daq)
install(FILES packaging/deb/caldaq.service DESTINATION /lib/systemd/system COMPONENT daq)
install(FILES packaging/deb/caldaq.conf DESTINATION /etc/caldaq COMPONENT daq)

set(CPACK_PACKAGE_NAME caldaq)
set(CPACK_PACKAGE_VENDOR caldaq)
set(CPACK_PACKAGE_CONTACT "caldaq maintainers <caldaq@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "machine-tool calibration: laser interferometer, environment and ballbar acquisition")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_GENERATOR DEB)
# Binaries without their debug information: the build type keeps it (RelWithDebInfo), and daq
# with it is 300 MB; the shop-floor package needs the program, not its symbols.
set(CPACK_STRIP_FILES ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
# The Python package when it is built (python/CMakeLists.txt: pybind11 and Python's headers).
if(TARGET _caldaq)
  set(CPACK_COMPONENTS_ALL daq python)
else()
  set(CPACK_COMPONENTS_ALL daq)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_DAQ_PACKAGE_NAME caldaq)
set(CPACK_DEBIAN_DAQ_PACKAGE_DEPENDS "adduser")
# PDF reports print through headless Chromium: recommended, not required.
set(CPACK_DEBIAN_DAQ_PACKAGE_RECOMMENDS "chromium, systemd, udev")
set(CPACK_COMPONENT_DAQ_DESCRIPTION
    "daq, the command line and the operator's page (daq serve as the caldaq service), with\n"
    "udev rules for the USB/HID instruments, manual pages and bash completion.")
set(CPACK_DEBIAN_DAQ_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/packaging/deb/postinst ${PROJECT_SOURCE_DIR}/packaging/deb/prerm
    ${PROJECT_SOURCE_DIR}/packaging/deb/postrm ${PROJECT_SOURCE_DIR}/packaging/deb/conffiles)
set(CPACK_DEBIAN_DAQ_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-caldaq)
set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3 (>= 3.11), python3 (<< 3.12), python3-numpy")
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_COMPONENT_PYTHON_DESCRIPTION
    "import caldaq: the run database, the analysis library, the model and the drivers' decoders\n"
    "from Python (docs/python.md).")
# What is packaged is built by scripts/package (daq, the Python module, the pages), not the
# whole test suite: `cpack` installs without building "all" first.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY ON)
include(CPack)
