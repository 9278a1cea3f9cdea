" Run by tests/lsp/editors_test.cpp inside `vim -es` with editors/vim and Debian's ALE
" (vim-ale) loaded and a mission open: lints it through `eamos lsp` (ALE's eamos linter,
" editors/vim/ale_linters/eamos/eamos.vim) and writes to $EAMOS_OUT one `LINE:COL TYPE TEXT`
" per diagnostic, then the project root ALE gave the server. Waits for the server's answer
" (at most 20 s), not for a time.
let g:ale_eamos_executable = $EAMOS_BIN
let g:ale_eamos_fleet = $EAMOS_FLEET
ALELint
let s:tries = 0
while empty(ale#engine#GetLoclist(bufnr(''))) && s:tries < 400
  sleep 50m
  let s:tries += 1
endwhile
let s:out = map(copy(ale#engine#GetLoclist(bufnr(''))), {_, d -> d.lnum . ':' . d.col . ' ' . d.type . ' ' . d.text})
call add(s:out, 'root ' . ale_linters#eamos#eamos#ProjectRoot(bufnr('')))
call writefile(s:out, $EAMOS_OUT)
