-- Neovim's built-in LSP client for eamos missions: require('eamos').setup{} starts `eamos lsp`
-- for every buffer of filetype eamos (one server per project root). Options:
--   cmd    the command, default { 'eamos', 'lsp' }
--   fleet  fleet file to check against, as `eamos check --fleet`; relative to the root
--   root   function(path) -> the project root; default: the folder holding .git, else the file's
-- Works from Neovim 0.7 (Debian 12) on.
local M = {}

local function default_root(path)
  -- .git is a folder in a clone and a file in a worktree.
  local here = vim.fn.fnamemodify(path, ':p:h') .. ';'
  local git = vim.fn.finddir('.git', here)
  if git ~= '' then return vim.fn.fnamemodify(git, ':p:h:h') end
  git = vim.fn.findfile('.git', here)
  return vim.fn.fnamemodify(git ~= '' and git or path, ':p:h')
end

local clients = {}  -- root -> client id, for Neovim 0.7, which has no vim.lsp.start

function M.setup(opts)
  opts = opts or {}
  vim.api.nvim_create_autocmd('FileType', {
    pattern = 'eamos',
    callback = function(args)
      local root = (opts.root or default_root)(vim.api.nvim_buf_get_name(args.buf))
      local config = {
        name = 'eamos',
        cmd = opts.cmd or { 'eamos', 'lsp' },
        root_dir = root,
        init_options = opts.fleet and { fleet = opts.fleet } or vim.empty_dict(),
      }
      if vim.lsp.start then
        vim.lsp.start(config, { bufnr = args.buf })
      else
        clients[root] = clients[root] or vim.lsp.start_client(config)
        vim.lsp.buf_attach_client(args.buf, clients[root])
      end
    end,
  })
end

return M
