# One interface target carries nave's warning and sanitizer flags; every nave target links it.
add_library(nave_warnings INTERFACE)
target_compile_options(nave_warnings INTERFACE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
if(NAVE_WERROR)
  target_compile_options(nave_warnings INTERFACE -Werror)
endif()
if(NAVE_SANITIZE)
  target_compile_options(nave_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                  -fno-sanitize-recover=undefined)
  target_link_options(nave_warnings INTERFACE -fsanitize=address,undefined)
endif()
