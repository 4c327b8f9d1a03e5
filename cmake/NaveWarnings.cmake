# One interface target carries nave's warning and sanitizer flags; every nave target links it.
add_library(nave_warnings INTERFACE)
target_compile_options(nave_warnings INTERFACE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
if(NAVE_WERROR)
  # GCC 12 reports maybe-uninitialized through std::optional<std::variant<...>> at -O3 where every path
  # initializes (a known false positive of that release); keep it visible but not fatal.
  target_compile_options(nave_warnings INTERFACE -Werror -Wno-error=maybe-uninitialized)
endif()
if(NAVE_SANITIZE)
  target_compile_options(nave_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                  -fno-sanitize-recover=undefined)
  target_link_options(nave_warnings INTERFACE -fsanitize=address,undefined)
endif()
if(NAVE_SANITIZE_THREAD)
  target_compile_options(nave_warnings INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(nave_warnings INTERFACE -fsanitize=thread)
endif()
