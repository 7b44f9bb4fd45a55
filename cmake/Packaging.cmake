# Install rules and the Debian package (CPack DEB): `cmake --build build/release --target package` writes
# build/release/avatarbooth_<version>_<arch>.deb. Installed layout (prefix /usr):
#   /usr/bin/avatarbooth, /etc/avatarbooth/booth.toml (conffile), /usr/share/avatarbooth/strings.toml + stage.map,
#   /usr/lib/systemd/system/avatarbooth.service (+ avatarbooth-retention.service/.timer, avatarbooth-share.service),
#   /usr/share/avatarbooth/model-viewer/ (the visitors' pages' 3-D viewer), /usr/lib/tmpfiles.d/avatarbooth.conf,
#   /usr/lib/sysusers.d/avatarbooth.conf, /usr/lib/udev/rules.d/60-avatarbooth.rules,
#   /usr/share/avatarbooth/firmware/ (overlay source, .dtbo when dtc was found, config.txt fragment),
#   /usr/share/doc/avatarbooth/ (README, copyright).
# The strings file is found next to the binary (StringTable::defaultFile: <bin>/../share/avatarbooth), so an
# unpacked package works from any root.

# The build tree mirrors that layout for the strings file (build/release/app/avatarbooth finds
# build/release/share/avatarbooth/strings.toml), so the built binary runs from any working directory.
configure_file(${CMAKE_SOURCE_DIR}/app/assets/strings.toml ${CMAKE_BINARY_DIR}/share/avatarbooth/strings.toml COPYONLY)
configure_file(${CMAKE_SOURCE_DIR}/app/assets/stage.map ${CMAKE_BINARY_DIR}/share/avatarbooth/stage.map COPYONLY)

# `install` (and cpack's preinstall step) builds nothing: the package test runs cpack on a built tree, and a full
# rebuild of every target there would take the CI's time.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY TRUE)

install(TARGETS avatarbooth RUNTIME DESTINATION bin)
install(FILES ${CMAKE_SOURCE_DIR}/app/assets/strings.toml ${CMAKE_SOURCE_DIR}/app/assets/stage.map DESTINATION share/avatarbooth)
# The config lives in /etc whatever the prefix: it is the operator's file (a dpkg conffile, kept on upgrade).
install(FILES ${CMAKE_SOURCE_DIR}/app/assets/booth.toml DESTINATION /etc/avatarbooth)
install(FILES ${CMAKE_SOURCE_DIR}/systemd/avatarbooth.service ${CMAKE_SOURCE_DIR}/systemd/avatarbooth-retention.service
              ${CMAKE_SOURCE_DIR}/systemd/avatarbooth-retention.timer ${CMAKE_SOURCE_DIR}/systemd/avatarbooth-share.service
        DESTINATION lib/systemd/system)
# <model-viewer> (npm, Apache-2.0, bundling three.js, MIT) for the visitors' pages (`avatarbooth share`) and the batch
# report: installed when tests/setup.sh has fetched it; without it the pages offer the downloads only.
set(AVATARBOOTH_MODEL_VIEWER_JS ${CMAKE_SOURCE_DIR}/app/assets/report/node_modules/@google/model-viewer/dist/model-viewer-umd.min.js)
if(EXISTS ${AVATARBOOTH_MODEL_VIEWER_JS})
  install(FILES ${AVATARBOOTH_MODEL_VIEWER_JS} DESTINATION share/avatarbooth/model-viewer)
endif()
install(FILES ${CMAKE_SOURCE_DIR}/systemd/avatarbooth.tmpfiles DESTINATION lib/tmpfiles.d RENAME avatarbooth.conf)
install(FILES ${CMAKE_SOURCE_DIR}/systemd/avatarbooth.sysusers DESTINATION lib/sysusers.d RENAME avatarbooth.conf)
install(FILES ${CMAKE_SOURCE_DIR}/firmware/60-avatarbooth.rules DESTINATION lib/udev/rules.d)
install(FILES ${CMAKE_SOURCE_DIR}/firmware/avatarbooth-overlay.dts ${CMAKE_SOURCE_DIR}/firmware/config.txt.fragment
        DESTINATION share/avatarbooth/firmware)
install(FILES ${CMAKE_SOURCE_DIR}/README.md ${CMAKE_SOURCE_DIR}/packaging/copyright DESTINATION share/doc/avatarbooth)

# The compiled overlay, when the device-tree compiler is there (Debian: device-tree-compiler).
find_program(DTC_EXECUTABLE dtc)
if(DTC_EXECUTABLE)
  add_custom_command(OUTPUT ${CMAKE_BINARY_DIR}/firmware/avatarbooth.dtbo
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/firmware
    COMMAND ${DTC_EXECUTABLE} -@ -q -I dts -O dtb -o ${CMAKE_BINARY_DIR}/firmware/avatarbooth.dtbo
            ${CMAKE_SOURCE_DIR}/firmware/avatarbooth-overlay.dts
    DEPENDS ${CMAKE_SOURCE_DIR}/firmware/avatarbooth-overlay.dts
    COMMENT "dtc: firmware/avatarbooth-overlay.dts")
  add_custom_target(firmware_overlay ALL DEPENDS ${CMAKE_BINARY_DIR}/firmware/avatarbooth.dtbo)
  install(FILES ${CMAKE_BINARY_DIR}/firmware/avatarbooth.dtbo DESTINATION share/avatarbooth/firmware)
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME avatarbooth)
set(CPACK_PACKAGE_VENDOR "avatarbooth")
set(CPACK_PACKAGE_CONTACT "avatarbooth maintainers <avatarbooth@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "photo-booth kiosk that turns a front and a side photo into a 3-D head")
set(CPACK_PACKAGE_DESCRIPTION "A visitor presses a button, a front and a side photo are taken, and a textured
 3-D head avatar is fitted (NTT method) and shown turning on the booth's screen. Runs as the systemd service
 avatarbooth.service (not enabled on install: systemctl enable --now avatarbooth avatarbooth-retention.timer). Run `avatarbooth check` first.
 The visitors' own pages (a QR code on the thanks screen) are off unless [share] is enabled in booth.toml and
 avatarbooth-share.service is enabled.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# Debug info stays in the build tree: the booth needs none of it.
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Shared libraries from dpkg-shlibdeps (dpkg-dev, part of build-essential); what is loaded at run time by path
# (the landmark model, fonts, Mesa's EGL and GL drivers) and the tools the maintainer scripts use, by name.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libdlib-data, opencv-data, fonts-dejavu-core, fonts-vlgothic, libegl-mesa0, libgl1-mesa-dri, sound-theme-freedesktop, systemd, udev")
# cups: the printed card ([print]) goes to a CUPS queue, on this machine or another (libcups2 itself comes from
# dpkg-shlibdeps).
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "device-tree-compiler, libcamera-tools, v4l-utils, gpiod, cups")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${CMAKE_SOURCE_DIR}/packaging/postinst ${CMAKE_SOURCE_DIR}/packaging/postrm ${CMAKE_SOURCE_DIR}/packaging/conffiles)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
