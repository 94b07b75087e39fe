# Numbers read from drapegen's JSON, shared by the end-to-end CLI scripts (include()d by them):
#
#   json_number(<var> <json> <member|index>...)
#
# sets <var> to the value at that path of <json> and stops the script unless it is a JSON number. nlohmann::json
# writes a NaN or an infinity as null, which string(JSON GET) returns as '', and no range check of LESS and GREATER
# fails on '': every number such a check reads comes through here.
#
#   json_boolean(<var> <json> <member|index>...)
#
# the same for a JSON true or false (<var> ON or OFF): a null is no false.
#
#   json_nano(<var> <number>)
#
# sets <var> to <number> (as string(JSON GET) writes one: 12, -0.10000000000000001, 1.0000000000000001e-05) in units
# of 1e-9, truncated toward zero and saturated at +-999999999999999999 (about 1e9): an integer for math(EXPR), which has
# no decimals, where a check needs a sum or a difference.
# The value at the path ARGN of <json> into <var>, unless its type is not <type> (what it is then: <what>).
function(_json_typed var json type what)
  string(REPLACE ";" " " where "${ARGN}")
  string(JSON found ERROR_VARIABLE missing TYPE "${json}" ${ARGN})
  if(missing)
    message(FATAL_ERROR "JSON '${where}': ${missing}")
  endif()
  string(JSON value GET "${json}" ${ARGN})
  if(NOT found STREQUAL type)
    message(FATAL_ERROR "JSON '${where}' is ${found} '${value}', ${what}")
  endif()
  set(${var} "${value}" PARENT_SCOPE)
endfunction()

function(json_number var json)
  _json_typed(value "${json}" NUMBER "not a number (NaN and infinities are written as null)" ${ARGN})
  set(${var} "${value}" PARENT_SCOPE)
endfunction()

function(json_boolean var json)
  _json_typed(value "${json}" BOOLEAN "not true or false" ${ARGN})
  set(${var} "${value}" PARENT_SCOPE)
endfunction()

function(json_nano var number)
  if(NOT number MATCHES "^(-?)([0-9]+)(\\.([0-9]+))?([eE][+]?(-?[0-9]+))?$")
    message(FATAL_ERROR "json_nano: '${number}' is not a number")
  endif()
  set(sign "${CMAKE_MATCH_1}")
  set(digits "${CMAKE_MATCH_2}${CMAKE_MATCH_4}")
  string(LENGTH "${CMAKE_MATCH_4}" decimals)
  set(exponent 0)
  if(NOT CMAKE_MATCH_6 STREQUAL "")
    string(REGEX REPLACE "^(-?)0*([0-9])" "\\1\\2" exponent "${CMAKE_MATCH_6}")
  endif()
  math(EXPR shift "${exponent} + 9 - ${decimals}")
  string(LENGTH "${digits}" length)
  if(shift GREATER 0)
    string(REPEAT "0" ${shift} zeros)
    string(APPEND digits "${zeros}")
  elseif(shift LESS 0)
    math(EXPR keep "${length} + ${shift}")
    if(keep GREATER 0)
      string(SUBSTRING "${digits}" 0 ${keep} digits)
    else()
      set(digits "")
    endif()
  endif()
  string(REGEX REPLACE "^0+" "" digits "${digits}")
  string(LENGTH "${digits}" length)
  if(length EQUAL 0)
    set(${var} 0 PARENT_SCOPE)
    return()
  elseif(length GREATER 18)
    set(digits 999999999999999999)
  endif()
  set(${var} "${sign}${digits}" PARENT_SCOPE)
endfunction()

# The decimal of a non-negative whole number of nano-units (json_nano's inverse): 21500000 -> 0.021500000,
# 6500000001 -> 6.500000001.
function(nano_decimal var nano)
  if(NOT nano MATCHES "^[0-9]+$")
    message(FATAL_ERROR "nano_decimal: '${nano}' is not a non-negative whole number")
  endif()
  math(EXPR whole "${nano} / 1000000000")
  math(EXPR fraction "${nano} % 1000000000")
  string(LENGTH "${fraction}" length)
  math(EXPR pad "9 - ${length}")
  string(REPEAT "0" ${pad} zeros)
  set(${var} "${whole}.${zeros}${fraction}" PARENT_SCOPE)
endfunction()
