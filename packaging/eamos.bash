# bash completion for eamos                                  -*- shell-script -*-
# Installed as share/bash-completion/completions/eamos; or `source` this file.
#
# The subcommands, their options and what each option takes are read from the installed
# command's own help (`eamos --help`, `eamos SUB --help`, once per shell), so the completion
# always matches the eamos it completes. What the help cannot say is written here: which files
# a mission, a trace, a fleet or a DDS configuration is.
#   eamos <TAB>                  check compile graph run ...
#   eamos graph m.eamos --kind <TAB>    amt meg mdg
#   eamos run <TAB>              *.eamos files and folders
#   eamos launch <TAB>           folders

# The help text of `eamos $1 --help` (`eamos --help` for ""), cached in _eamos_help_<sub>.
_eamos_help() {
    local var="_eamos_help_${1//-/_}"
    if [[ -z ${!var+set} ]]; then
        declare -g "$var=$(command eamos ${1:+"$1"} --help 2>/dev/null)"
    fi
    printf '%s\n' "${!var}"
}

# Lines of section "$2:" (Options, Positionals, Subcommands) of the help of "$1".
_eamos_section() {
    local line in=0
    while IFS= read -r line; do
        if [[ $line == "$2:" ]]; then in=1; continue; fi
        [[ $line =~ ^[A-Z][a-z]*:$ ]] && in=0
        ((in)) && printf '%s\n' "$line"
    done < <(_eamos_help "$1")
}

_eamos_subcommands() {
    local line
    while IFS= read -r line; do
        [[ $line =~ ^\ \ ([a-z][a-z0-9-]*)\ \  ]] && printf '%s\n' "${BASH_REMATCH[1]}"
    done < <(_eamos_section "" Subcommands)
}

# Every option name of subcommand $1 ("" for eamos itself), one a line.
_eamos_options() {
    local line
    while IFS= read -r line; do
        if [[ $line =~ ^\ \ (-[A-Za-z],)?(--[A-Za-z0-9-]+) ]]; then
            [[ -n ${BASH_REMATCH[1]} ]] && printf '%s\n' "${BASH_REMATCH[1]%,}"
            printf '%s\n' "${BASH_REMATCH[2]}"
        fi
    done < <(_eamos_section "$1" Options)
}

# What option $2 of subcommand $1 takes: "flag", or its type as the help writes it (TEXT:FILE,
# TEXT:FOLDER, TEXT:amt|meg|mdg, UINT=200, INT:WHOLE, TEXT, ...): the upper-case word after the
# names. A flag's names may be followed by "Excludes: ..." or "Needs: ...", which is no type.
# CLI11 writes names and type in a column 30 wide, the description after it (or on the next line).
_eamos_option_type() {
    local line left
    while IFS= read -r line; do
        left=$line
        [[ ${#line} -gt 30 && ${line:29:1} == " " && ${line:30:1} != " " ]] && left=${line:0:30}
        [[ $left =~ ^\ \ ((-[A-Za-z],)?--[A-Za-z0-9-]+)(\ ([A-Z]+([:=][^ ]*)?)(\ |$))? ]] || continue
        [[ ",${BASH_REMATCH[1]}," == *",$2,"* ]] || continue
        printf '%s\n' "${BASH_REMATCH[4]:-flag}"
        return
    done < <(_eamos_section "$1" Options)
}

# The type of the $2-th positional (from 1) of subcommand $1, with its name: "mission TEXT:FILE".
_eamos_positional() {
    local line n=0
    while IFS= read -r line; do
        [[ $line =~ ^\ \ ([a-z][a-z0-9_-]*)\ ([A-Z]+(:[^ ]*)?) ]] || continue
        ((++n == $2)) && { printf '%s %s\n' "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}"; return; }
    done < <(_eamos_section "$1" Positionals)
}

# Adds the completions of a value to COMPREPLY: $1 the option or positional name, $2 its type
# (a default after '=' dropped).
_eamos_values() {
    local name=$1 type=${2%%=*} cur=$3 ext=""
    case $name in
        mission) ext='*.eamos' ;;
        trace) ext='*.jsonl' ;;
        --fleet) ext='*.y?(a)ml' ;;
        --dds-config) ext='*.xml' ;;
    esac
    case $type in
        *:*\|*) local words=${type#*:}
               COMPREPLY+=($(compgen -W "${words//|/ }" -- "$cur")) ;;
        *:FOLDER) compopt -o filenames 2>/dev/null
               COMPREPLY+=($(compgen -d -- "$cur")) ;;
        TEXT|TEXT:FILE)
            compopt -o filenames 2>/dev/null
            if [[ -n $ext ]]; then
                local IFS=$'\n'
                COMPREPLY+=($(shopt -s extglob; compgen -f -X "!$ext" -- "$cur") $(compgen -d -- "$cur"))
            else
                COMPREPLY+=($(compgen -f -- "$cur"))
            fi ;;
    esac    # numbers and anything else: nothing to offer
}

_eamos() {
    local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} sub="" i word
    COMPREPLY=()
    # --opt=value: bash splits at '=' (COMP_WORDBREAKS); the value is completed once begun.
    [[ $cur == "=" ]] && return 0
    if [[ $prev == "=" && COMP_CWORD -ge 2 ]]; then prev=${COMP_WORDS[COMP_CWORD-2]}; fi
    local subs
    subs=$(_eamos_subcommands)
    for ((i = 1; i < COMP_CWORD; i++)); do
        word=${COMP_WORDS[i]}
        if [[ $word != -* && $'\n'$subs$'\n' == *$'\n'$word$'\n'* ]]; then sub=$word; break; fi
    done
    # The value of an option, of eamos's own (--color) before the subcommand or of the subcommand's.
    if [[ $prev == -* ]]; then
        local type
        type=$(_eamos_option_type "$sub" "$prev")
        if [[ -n $type && $type != flag ]]; then
            _eamos_values "$prev" "$type" "$cur"
            return 0
        fi
    fi
    if [[ -z $sub ]]; then
        COMPREPLY=($(compgen -W "$subs $(_eamos_options "")" -- "$cur"))
        return 0
    fi
    if [[ $cur == -* ]]; then
        COMPREPLY=($(compgen -W "$(_eamos_options "$sub")" -- "$cur"))
        return 0
    fi
    # A positional: count the words after the subcommand that are not options or their values.
    local n=1 t
    for ((i = i + 1; i < COMP_CWORD; i++)); do
        word=${COMP_WORDS[i]}
        if [[ $word == -* ]]; then
            t=$(_eamos_option_type "$sub" "$word")
            [[ -n $t && $t != flag ]] && ((i++))
        elif [[ $word != "=" ]]; then
            ((n++))
        fi
    done
    local positional
    positional=$(_eamos_positional "$sub" "$n")
    [[ -n $positional ]] && _eamos_values "${positional%% *}" "${positional#* }" "$cur"
    return 0
}
complete -F _eamos eamos
