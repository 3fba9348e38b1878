# Writes a C++ file defining `extern const char SYMBOL[]` as the bytes of IN (NUL-terminated), so a
# text kept as its own source file (the HTML replay page) is part of the binary.
# Usage: cmake -DIN=file -DOUT=file.cpp -DSYMBOL=name -P embed_text.cmake
file(READ "${IN}" hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," hex "${hex}")
string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n" hex "${hex}")
file(WRITE "${OUT}.new" "// Generated from ${IN} by cmake/embed_text.cmake: do not edit.\nnamespace rm3d {\nextern const char ${SYMBOL}[];\nconst char ${SYMBOL}[] = {\n${hex}0x00};\n}  // namespace rm3d\n")
file(COPY_FILE "${OUT}.new" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.new")
