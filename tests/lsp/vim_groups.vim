" Run by tests/lsp/editors_test.cpp inside `vim -es`: writes to the file g:out the buffer's
" filetype, then `LINE:COL WORD GROUP` for each word and operator of the buffer (the syntax
" group at its first character), then any error message Vim gave.
let s:out = ['filetype ' . &filetype]
for s:lnum in range(1, line('$'))
  let s:text = getline(s:lnum)
  let s:start = 0
  while 1
    let s:m = matchstrpos(s:text, '\k\+\|&&\|||\|>=\|<=\|//\|/\*\|[-+*/<>!]', s:start)
    if s:m[1] < 0
      break
    endif
    call add(s:out, s:lnum . ':' . (s:m[1] + 1) . ' ' . s:m[0] . ' ' . synIDattr(synID(s:lnum, s:m[1] + 1, 1), 'name'))
    let s:start = s:m[2]
  endwhile
endfor
call add(s:out, 'errmsg ' . v:errmsg)
call writefile(s:out, g:out)
