# TOMORIG_SANITIZE: a comma-separated list of GCC/Clang sanitizers (e.g. "address,undefined")
# for every target of the tree. CI builds a second tree with it (scripts/setup.sh test runs
# scripts/test-sanitized.sh); docs/reliability.md says which suites run there and why.
set(TOMORIG_SANITIZE "" CACHE STRING "Sanitizers for every target, e.g. address,undefined (empty: none)")
if(TOMORIG_SANITIZE)
  # -O1 keeps the instrumented suites fast enough for CI while the reports keep usable stacks;
  # undefined behaviour is fatal (no recovery), so a test cannot pass over a report.
  add_compile_options(-fsanitize=${TOMORIG_SANITIZE} -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -O1 -g)
  add_link_options(-fsanitize=${TOMORIG_SANITIZE})
  # Tests and child processes started by tests read this to know what they run under.
  add_compile_definitions(TOMORIG_SANITIZED=1)
endif()
