" eamos missions: *.eamos files are of filetype eamos.
autocmd BufRead,BufNewFile *.eamos setfiletype eamos
