# bash completion for frep and frep-worker (frepfarm). Source it, or install it as
# /usr/share/bash-completion/completions/frep (and a link named frep-worker).
# tests/tools/docs_check.py checks that it offers every verb and option of `frep VERB --help`.

_frep_options() {
  local model="-o --object -a --params -x --map -i --iso"
  local region="-b --bounds --res -g --grid -O --out"
  local geometric="--t-frames --t-range --v-range --v-cells --w-range --w-cells --c-range --c-levels --g-values"
  local farm="--workers --threads --listen --expect-workers --brick --heartbeat-ms --resume --json --no-progress --curve --insecure --strict --verify --replicate"
  case "$1" in
    check) echo "-h --help -o --object -b --bounds" ;;
    eval) echo "-h --help $model --at --tolerance" ;;
    slice) echo "-h --help $model $region --axis --at --mask $geometric" ;;
    sample) echo "-h --help $model $region --band --store $farm" ;;
    mesh) echo "-h --help $model $region --tolerance --no-sharp --open-rim --format --up --wrl --stl --stlb --pov --cli --gs --timing $farm" ;;
    render) echo "-h --help $model -b --bounds -O --out --size --azimuth --elevation --distance --zoom --eye --target --up --perspective --fov --background --colour --color --frames --no-footprint $geometric $farm" ;;
    pov) echo "-h --help -o --object -O --out --thin" ;;
    relate) echo "-h --help --object-a --object-b -b --bounds --min-size --at --distance-tol --json" ;;
    measure) echo "-h --help $model -b --bounds --tolerance --threads --max-cells --json --no-progress" ;;
    view) echo "-h --help $model -b --bounds --res -g --grid --workers --host --port" ;;
    keygen) echo "-h --help --force" ;;
  esac
}

_frep() {
  local cur prev verb i
  cur="${COMP_WORDS[COMP_CWORD]}"
  prev="${COMP_WORDS[COMP_CWORD-1]}"
  local verbs="check eval slice sample mesh render pov relate measure view keygen"
  for ((i = 1; i < COMP_CWORD; i++)); do
    case "${COMP_WORDS[i]}" in
      --log-level) ((i++)) ;;
      -*) ;;
      *) verb="${COMP_WORDS[i]}"; break ;;
    esac
  done
  case "$prev" in
    --log-level) COMPREPLY=($(compgen -W "trace debug info warn error critical off" -- "$cur")); return ;;
    --store) COMPREPLY=($(compgen -W "sdf sdf-exact raw fog" -- "$cur")); return ;;
    --axis) COMPREPLY=($(compgen -W "x y z" -- "$cur")); return ;;
    --format) COMPREPLY=($(compgen -W "ply obj stl stl-ascii wrl pov 3mf glb cli cli-binary" -- "$cur")); return ;;
    --wrl|--stl|--stlb|--pov|--cli) COMPREPLY=($(compgen -f -- "$cur")); return ;;
    -O|--out) COMPREPLY=($(compgen -f -- "$cur")); return ;;
    --curve) COMPREPLY=($(compgen -d -- "$cur")); return ;;
    --replicate) COMPREPLY=($(compgen -W "1 2" -- "$cur")); return ;;
    -o|--object|--object-a|--object-b|-a|--params|-x|--map|-i|--iso|-b|--bounds|--res|-g|--grid|--at|--tolerance|\
    --gs|--up|--size|--azimuth|--elevation|--distance|--zoom|--eye|--target|--fov|--background|--colour|--color|--frames|\
    --t-frames|--t-range|--v-range|--v-cells|--w-range|--w-cells|--c-range|--c-levels|--g-values|\
    --band|--workers|--threads|--listen|--expect-workers|--brick|--heartbeat-ms|--thin|--min-size|--verify|--max-cells|\
    --host|--port)
      return ;;  # a value: nothing to offer
  esac
  if [[ -z "$verb" ]]; then
    if [[ "$cur" == -* ]]; then
      COMPREPLY=($(compgen -W "-h --help --version --log-level" -- "$cur"))
    else
      COMPREPLY=($(compgen -W "$verbs" -- "$cur"))
    fi
    return
  fi
  if [[ "$cur" == -* ]]; then
    COMPREPLY=($(compgen -W "$(_frep_options "$verb")" -- "$cur"))
  elif [[ "$verb" == keygen ]]; then
    COMPREPLY=($(compgen -d -- "$cur"))
  elif [[ "$verb" == mesh ]]; then
    COMPREPLY=($(compgen -f -X '!*.@(hf|vdb)' -- "$cur") $(compgen -d -- "$cur"))
  elif [[ "$verb" == render ]]; then
    COMPREPLY=($(compgen -f -X '!*.@(hf|vdb|ply|obj|stl)' -- "$cur") $(compgen -d -- "$cur"))
  elif [[ "$verb" == pov ]]; then
    COMPREPLY=($(compgen -f -X '!*.@(hf|pov)' -- "$cur") $(compgen -d -- "$cur"))
  else
    COMPREPLY=($(compgen -f -X '!*.hf' -- "$cur") $(compgen -d -- "$cur"))
  fi
}

_frep_worker() {
  local cur="${COMP_WORDS[COMP_CWORD]}" prev="${COMP_WORDS[COMP_CWORD-1]}"
  case "$prev" in
    --log-level) COMPREPLY=($(compgen -W "trace debug info warn error critical off" -- "$cur")); return ;;
    --curve|--data-dir) COMPREPLY=($(compgen -d -- "$cur")); return ;;
    --connect|--threads|--master-timeout) return ;;
  esac
  COMPREPLY=($(compgen -W "-h --help --version --connect --threads --curve --master-timeout --data-dir --log-level" -- "$cur"))
}

shopt -s extglob 2>/dev/null
complete -o filenames -F _frep frep
complete -F _frep_worker frep-worker
