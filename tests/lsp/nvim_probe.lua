-- Run by tests/lsp/editors_test.cpp inside `nvim --headless` with editors/vim on the
-- runtimepath, require('eamos').setup{} done and a mission open: waits (at most 20 s) for
-- the diagnostics of `eamos lsp`, asks for a hover and a definition, and writes the answers
-- to $EAMOS_OUT, one per line.
local out = {}
vim.wait(20000, function() return #vim.diagnostic.get(0) > 0 end, 20)
for _, d in ipairs(vim.diagnostic.get(0)) do
  table.insert(out, string.format('diagnostic %d:%d %s', d.lnum, d.col, d.message))
end
local doc = { uri = vim.uri_from_bufnr(0) }
local function ask(method, line, character)
  local answers = vim.lsp.buf_request_sync(0, method, { textDocument = doc, position = { line = line, character = character } }, 20000)
  for _, a in pairs(answers or {}) do return a.result end
end
local hover = ask('textDocument/hover', tonumber(vim.env.HOVER_LINE), tonumber(vim.env.HOVER_CHAR))
table.insert(out, 'hover ' .. (hover and hover.contents.value:gsub('\n', ' ') or 'none'))
local def = ask('textDocument/definition', tonumber(vim.env.DEF_LINE), tonumber(vim.env.DEF_CHAR))
table.insert(out, 'definition ' .. (def and string.format('%d:%d', def.range.start.line, def.range.start.character) or 'none'))
vim.fn.writefile(out, vim.env.EAMOS_OUT)
