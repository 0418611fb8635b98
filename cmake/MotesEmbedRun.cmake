# Script mode helper of motes_embed_text: writes OUTPUT with the bytes of INPUT as SYMBOL.
file(READ ${INPUT} hex HEX)
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
string(REGEX REPLACE "(0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,0x..,)" "\\1\n  "
       bytes "${bytes}")
file(WRITE ${OUTPUT} "// Generated from ${INPUT} by cmake/MotesEmbedRun.cmake. Do not edit.\n"
     "extern const char ${SYMBOL}[];\nconst char ${SYMBOL}[] = {\n  ${bytes}0x00};\n")
