# Read by cpack (CPACK_PROJECT_CONFIG_FILE) each time it makes the package, not when CMake
# configures: the version and the changelog follow the commit the package is made from, even in a
# build tree configured several commits ago.
#   0.1.0+git<commits>.<hash>: dpkg compares the commit count first, so a package made from a later
#   commit upgrades one made from an earlier.
execute_process(COMMAND git -C "${CPACK_SALIENT_SOURCE_DIR}" log -1 --format=%h%n%cD --abbrev=8
                OUTPUT_VARIABLE head OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE git_failed)
execute_process(COMMAND git -C "${CPACK_SALIENT_SOURCE_DIR}" rev-list --count HEAD
                OUTPUT_VARIABLE count OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
set(hash "unknown")
string(TIMESTAMP date "%a, %d %b %Y %H:%M:%S +0000" UTC)
if(NOT git_failed AND head AND count)
  string(REPLACE "\n" ";" head "${head}")
  list(GET head 0 hash)
  list(GET head 1 date)
  set(CPACK_PACKAGE_VERSION "${CPACK_SALIENT_UPSTREAM_VERSION}+git${count}.${hash}")
else()
  set(CPACK_PACKAGE_VERSION "${CPACK_SALIENT_UPSTREAM_VERSION}")
endif()
set(CPACK_DEBIAN_PACKAGE_VERSION "${CPACK_PACKAGE_VERSION}")

# /usr/share/doc/salient/changelog.gz (a native package's name; gzip -9n: reproducible).
file(READ "${CPACK_SALIENT_SOURCE_DIR}/deploy/debian/changelog" changelog)
string(REPLACE "@DEB_VERSION@" "${CPACK_PACKAGE_VERSION}" changelog "${changelog}")
string(REPLACE "@GIT_DESCRIBE@" "${hash}" changelog "${changelog}")
string(REPLACE "@DEB_DATE@" "${date}" changelog "${changelog}")
file(WRITE "${CPACK_SALIENT_DOC_DIR}/changelog" "${changelog}")
execute_process(COMMAND gzip -9nf "${CPACK_SALIENT_DOC_DIR}/changelog")
