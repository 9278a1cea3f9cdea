" Vim syntax file for eamos missions (.eamos): the mission language of docs/language.md.
" Highlighting only; diagnostics, hover and completion come from `eamos lsp` (docs/editors.md).
if exists('b:current_syntax')
  finish
endif

syntax keyword eamosKeyword package var func
syntax keyword eamosAsync async
syntax keyword eamosBoolean true false
syntax keyword eamosControl If WaitUntil WaitWhile RepeatUntil RepeatWhile RepeatFor
syntax keyword eamosControl PauseUntil PauseWhile PauseFor
syntax keyword eamosControl DoUntilAsync DoWhileAsync DoUntilSync DoWhileSync

" Blocks: INIT, SEQ_* and PAR_*, where they are declared and where they are called.
syntax match eamosBlock /\<\(INIT\|SEQ_\w\+\|PAR_\w\+\)\>/
" Drone.Capability: the capability after the dot.
syntax match eamosCapability /\(\<\h\w*\s*\.\s*\)\@<=\h\w*/
" var Drone Type: the type after the drone's name.
syntax match eamosType /\(\<var\s\+\h\w*\s\+\)\@<=\h\w*/

syntax match eamosNumber /\<\d\+\(\.\d*\)\=\([eE][-+]\=\d\+\)\=\>/
syntax match eamosNumber /\.\d\+\([eE][-+]\=\d\+\)\=\>/
syntax match eamosOperator /&&\|||\|==\|!=\|<=\|>=\|[-+*/<>!]/

syntax keyword eamosTodo contained TODO FIXME XXX NOTE
syntax region eamosComment start=+//+ end=+$+ contains=eamosTodo,@Spell
syntax region eamosComment start=+/\*+ end=+\*/+ contains=eamosTodo,@Spell

highlight default link eamosKeyword Keyword
highlight default link eamosAsync Keyword
highlight default link eamosBoolean Boolean
highlight default link eamosControl Conditional
highlight default link eamosBlock Function
highlight default link eamosCapability Identifier
highlight default link eamosType Type
highlight default link eamosNumber Number
highlight default link eamosOperator Operator
highlight default link eamosTodo Todo
highlight default link eamosComment Comment

let b:current_syntax = 'eamos'
