" ALE (dense-analysis/ale; Debian: vim-ale) runs `eamos lsp` for eamos missions: diagnostics
" as you type, and :ALEHover, :ALEGoToDefinition and completion. Settings:
"   g:ale_eamos_executable  the eamos command (default 'eamos')
"   g:ale_eamos_fleet       fleet file to check against, as `eamos check --fleet`; relative to
"                           the project root (the folder holding .git, else the mission's)
call ale#Set('eamos_executable', 'eamos')
call ale#Set('eamos_fleet', '')

function! ale_linters#eamos#eamos#ProjectRoot(buffer) abort
  " .git is a folder in a clone and a file in a worktree.
  let l:here = fnameescape(fnamemodify(bufname(a:buffer), ':p:h')) . ';'
  let l:git = finddir('.git', l:here)
  if !empty(l:git)
    return fnamemodify(l:git, ':p:h:h')
  endif
  let l:git = findfile('.git', l:here)
  return fnamemodify(empty(l:git) ? bufname(a:buffer) : l:git, ':p:h')
endfunction

function! ale_linters#eamos#eamos#Options(buffer) abort
  let l:fleet = ale#Var(a:buffer, 'eamos_fleet')
  return empty(l:fleet) ? {} : {'fleet': l:fleet}
endfunction

call ale#linter#Define('eamos', {
\   'name': 'eamos',
\   'lsp': 'stdio',
\   'executable': {buffer -> ale#Var(buffer, 'eamos_executable')},
\   'command': '%e lsp',
\   'project_root': function('ale_linters#eamos#eamos#ProjectRoot'),
\   'initialization_options': function('ale_linters#eamos#eamos#Options'),
\})
