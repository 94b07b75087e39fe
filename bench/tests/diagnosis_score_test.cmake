# drapegen_diagnosis_bench --score-only on hand-written reports and truth files (no simulation): the confusion
# matrix and the split of detection from attribution count what the reports say.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/diagnoses ${WORK}/truth ${WORK}/screen)

# One report, its truth file (the effect's region: skirt) and its screen record: CASE, its family, the verdict,
# whether the gate found it within the floors, the localised region, the kept draw's excess at the screen.
function(write_case name family verdict within region excess)
  file(WRITE ${WORK}/screen/${name}.json "[{\"draw\": 0, \"visible\": true, \"excess\": ${excess}}]")
  file(WRITE ${WORK}/diagnoses/${name}.json
       "{\"verdict\": \"${verdict}\", \"within_floors\": ${within}, \"shrinkage\": 1.0,
         \"localisation\": {\"region\": \"${region}\"}, \"gap_mm\": {\"all_views\": 5.0},
         \"floors\": {\"all_views_mm\": 4.0}, \"runtime\": {\"seconds\": 10.0}}")
  file(WRITE ${WORK}/truth/${name}.json
       "{\"family\": \"${family}\", \"regions\": [\"skirt\"], \"effects\": [{\"name\": \"${family}\", \"strength\": 1}]}")
endfunction()

write_case(yield_00 yield none true hem 0.05)       # within the floors at the gate
write_case(yield_01 yield none false skirt 0.2)     # within them once the bending alone is refitted
write_case(yield_02 yield yield false skirt 0.5)    # found, named right, its region right
write_case(shear_00 shear curl false hem 0.3)       # found, named wrong, its region wrong
# Within the floors at the gate, named yield by the turn-over (drapegen diagnose --turn-over-yield): named right, but
# not found above the floors.
write_case(yield_03 yield yield true hem 0.05)
file(READ ${WORK}/diagnoses/yield_03.json turned)
string(JSON turned SET "${turned}" turn_over "{\"rise\": 0.05, \"floor\": 0.02, \"refits_verdict\": \"none\"}")
file(WRITE ${WORK}/diagnoses/yield_03.json "${turned}")
# Within the floors at the gate, named misalignment by the hem's centre (--off-centre-misalignment): named wrong here.
write_case(shear_02 shear misalignment true hem 0.05)
file(READ ${WORK}/diagnoses/shear_02.json centred)
string(JSON centred SET "${centred}" off_centre "{\"ratio\": 3.0, \"floor\": 2.5, \"refits_verdict\": \"none\"}")
file(WRITE ${WORK}/diagnoses/shear_02.json "${centred}")
# Above the floors, the refits' yield withdrawn by the turn-over's alternation (--turn-over-alternation): unexplained,
# found above the floors, named wrong; and a control the alternation withdrew then the hem's centre named.
write_case(yield_04 yield unexplained false skirt 0.3)
file(READ ${WORK}/diagnoses/yield_04.json withdrawn)
string(JSON withdrawn SET "${withdrawn}" alternation
       "{\"alternation\": 0.004, \"floor\": 0.015, \"refits_verdict\": \"yield\"}")
file(WRITE ${WORK}/diagnoses/yield_04.json "${withdrawn}")
write_case(none_00 none misalignment false hem 0.3)
file(READ ${WORK}/diagnoses/none_00.json both)
string(JSON both SET "${both}" alternation "{\"alternation\": 0.004, \"floor\": 0.015, \"refits_verdict\": \"yield\"}")
string(JSON both SET "${both}" off_centre "{\"ratio\": 3.0, \"floor\": 2.5, \"refits_verdict\": \"unexplained\"}")
file(WRITE ${WORK}/diagnoses/none_00.json "${both}")
# Not a report the scorer reads (an older format, a stray file): said on stderr and left out of every count.
file(WRITE ${WORK}/diagnoses/shear_01.json "{\"verdict\": \"shear\"}")
file(WRITE ${WORK}/truth/shear_01.json "{\"family\": \"shear\", \"regions\": [\"skirt\"]}")

execute_process(COMMAND ${BENCH} --out ${WORK} --score-only --families yield shear --per-family 5 --controls 1
                        --fabrics ${FABRICS}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "--score-only failed (${code}): ${out} ${err}")
endif()
string(FIND "${err}" "shear_01.json: not a drapegen diagnose report" found)
if(found EQUAL -1)
  message(FATAL_ERROR "the incomplete report is not named on stderr:\n${err}")
endif()
foreach(needle
    "| none | 0 | 0 | 0 | 0 | 0 | 0 | 0 | 1 | 0 |"
    "| yield | 2 | 1 | 0 | 2 | 0 | 0 | 0 | 0 | 0 |"
    "| shear | 0 | 0 | 0 | 0 | 0 | 1 | 0 | 1 | 0 |"
    "top-1 correct on effect captures: 2/7 (29%)"
    "3 effect captures within the floors at the gate, 1 once the bending alone is refitted; of the 3 found above them, named correctly: 1 (33%)"
    "localised region matches the effect's region: 3/7 (shear 0/2, yield 3/5); on the 3 found above the floors: 2"
    "stable and shape terms summed): below 0.1: 1/3; 0.1 to 0.3: 0/1; from 0.3: 1/3"
    "controls within the floors: 0/1 (0%)"
    "| yield_03 | yield | 1 | yield (turn-over) |"
    "| yield_04 | yield | 1 | unexplained (alternation) |"
    "| none_00 | none | 1 | misalignment (hem centre) |"
    "| shear_02 | shear | 1 | misalignment (hem centre) |")
  string(FIND "${out}" "${needle}" found)
  if(found EQUAL -1)
    message(FATAL_ERROR "the score does not say '${needle}':\n${out}")
  endif()
endforeach()
