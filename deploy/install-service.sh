#!/usr/bin/env bash
# Installs (or updates) bodyscan as a system service on Debian 12: the `bodyscan`
# system user (groups plugdev, video), the binary, the browser UI, the systemd
# unit, the udev rules, the GigE sysctl settings and /etc/bodyscan. Build first
# (deploy/build.sh). Idempotent: run it again after every build; existing
# /etc/bodyscan files (rig.json, bodyscan.env) are never overwritten and a running
# service is not restarted (a scan may be in progress). See docs/deployment.md.
#
#   sudo deploy/install-service.sh              install or update, enable, start
#   sudo deploy/install-service.sh --no-start   install or update, enable only
#   deploy/install-service.sh --dry-run         print what it would do, change nothing
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { sed -n '2,12s/^# \{0,1\}//p' "$0"; }

DRY_RUN=0
START=1
for arg in "$@"; do
  case "$arg" in
    --dry-run) DRY_RUN=1 ;;
    --no-start) START=0 ;;
    -h | --help) usage; exit 0 ;;
    *) echo "install-service: unknown option '$arg'" >&2; usage >&2; exit 2 ;;
  esac
done

SERVICE_USER=bodyscan
BIN_SRC=${BIN_SRC:-build/app/bodyscan}
BIN_DEST=/usr/local/bin/bodyscan
WEB_SRC=${WEB_SRC:-build/web}
WEB_DEST=/usr/local/share/bodyscan/web
DOC_DEST=/usr/local/share/doc/bodyscan/deployment.md
UNIT_DEST=/etc/systemd/system/bodyscan.service
UDEV_DEST=/etc/udev/rules.d/60-bodyscan.rules
SYSCTL_DEST=/etc/sysctl.d/60-bodyscan-gige.conf
MODULES_DEST=/etc/modules-load.d/bodyscan.conf
CONF_DIR=/etc/bodyscan
DATA_DIR=/var/lib/bodyscan
EXAMPLE_RIG=hw/rigs/thesis.json

say() { echo "install-service: $*"; }
warn() { echo "install-service: warning: $*" >&2; }
die() { echo "install-service: error: $*" >&2; exit 1; }

# Runs a command, or only prints it with --dry-run.
run() {
  if ((DRY_RUN)); then
    printf '  would run:'
    printf ' %q' "$@"
    printf '\n'
  else
    "$@"
  fi
}

# install_file SRC DEST MODE: copies SRC to DEST (root-owned) unless DEST already
# has the same content and mode. Writes beside DEST and renames, so a running
# binary or a reading udev never sees half a file. Sets CHANGED=1 if it copied.
CHANGED=0
install_file() {
  local src=$1 dest=$2 mode=$3
  if [[ -f "$dest" ]] && cmp -s "$src" "$dest" &&
    [[ "$(stat -c '%a %U %G' "$dest")" == "${mode#0} root root" ]]; then
    say "unchanged: $dest"
    CHANGED=0
    return
  fi
  say "installing $src -> $dest (mode $mode)"
  run install -d -m 0755 "$(dirname "$dest")"
  run install -m "$mode" -o root -g root "$src" "$dest.new.$$"
  run mv -f "$dest.new.$$" "$dest"
  CHANGED=1
}

# write_new_file DEST MODE OWNER GROUP < CONTENT: creates DEST from stdin only if
# it does not exist yet (the administrator's edits are kept).
write_new_file() {
  local dest=$1 mode=$2 owner=$3 group=$4 content
  content=$(cat)
  if [[ -e "$dest" ]]; then
    say "kept existing $dest"
    return
  fi
  say "creating $dest (mode $mode, $owner:$group)"
  if ((DRY_RUN)); then return; fi
  (umask 077 && printf '%s\n' "$content" >"$dest.new.$$")
  chown "$owner:$group" "$dest.new.$$"
  chmod "$mode" "$dest.new.$$"
  mv -f "$dest.new.$$" "$dest"
}

# ---- checks --------------------------------------------------------------------
if [[ $(id -u) -ne 0 ]]; then
  if ((DRY_RUN)); then
    warn "not root: fine for --dry-run, but the real run needs root (sudo $0)"
  else
    die "must be run as root: sudo $0 $*"
  fi
fi
if ((DRY_RUN)); then say "dry run: nothing is changed"; fi

for f in deploy/systemd/bodyscan.service deploy/udev/60-bodyscan.rules \
  deploy/sysctl/60-bodyscan-gige.conf; do
  [[ -f "$f" ]] || die "missing $f (run from a complete checkout)"
done
if [[ ! -x "$BIN_SRC" ]]; then
  if ((DRY_RUN)); then
    warn "$BIN_SRC not built yet (deploy/build.sh); a real run would stop here"
  else
    die "$BIN_SRC not found: build first with deploy/build.sh"
  fi
elif ! "$BIN_SRC" serve --help >/dev/null 2>&1; then
  warn "$BIN_SRC has no working 'serve' command: installing, but not starting the service"
  START=0
fi

SYSTEMD_RUNNING=0
[[ -d /run/systemd/system ]] && SYSTEMD_RUNNING=1
HAVE_UDEVADM=0
command -v udevadm >/dev/null 2>&1 && HAVE_UDEVADM=1

# ---- user and groups -------------------------------------------------------------
if getent passwd "$SERVICE_USER" >/dev/null; then
  say "user $SERVICE_USER exists"
else
  say "creating system user $SERVICE_USER"
  run useradd --system --user-group --home-dir "$DATA_DIR" --no-create-home \
    --shell /usr/sbin/nologin --comment "bodyscan workstation server" "$SERVICE_USER"
fi
for group in plugdev video; do
  if ! getent group "$group" >/dev/null; then
    say "creating group $group"
    run groupadd --system "$group"
  fi
  member_of=" $(id -nG "$SERVICE_USER" 2>/dev/null || true) "
  if [[ "$member_of" == *" $group "* ]]; then
    say "user $SERVICE_USER is in group $group"
  else
    say "adding $SERVICE_USER to group $group"
    run usermod -a -G "$group" "$SERVICE_USER"
  fi
done

# ---- program, UI, documentation --------------------------------------------------
# Whether a running service runs an older binary, UI or unit than installed now.
RESTART_NEEDED=0
if [[ -x "$BIN_SRC" ]]; then
  install_file "$BIN_SRC" "$BIN_DEST" 0755
  RESTART_NEEDED=$CHANGED
fi

if [[ -d "$WEB_SRC" ]]; then
  if [[ -d "$WEB_DEST" ]] && diff -rq "$WEB_SRC" "$WEB_DEST" >/dev/null 2>&1; then
    say "unchanged: $WEB_DEST"
  else
    say "installing $WEB_SRC -> $WEB_DEST"
    run install -d -m 0755 "$(dirname "$WEB_DEST")"
    run rm -rf "$WEB_DEST.new"
    run cp -R "$WEB_SRC" "$WEB_DEST.new"
    run chmod -R u=rwX,go=rX "$WEB_DEST.new"
    run rm -rf "$WEB_DEST.old"
    if [[ -d "$WEB_DEST" ]]; then run mv "$WEB_DEST" "$WEB_DEST.old"; fi
    run mv "$WEB_DEST.new" "$WEB_DEST"
    run rm -rf "$WEB_DEST.old"
    RESTART_NEEDED=1
  fi
else
  warn "$WEB_SRC not found: the browser UI is not installed (the unit serves $WEB_DEST)"
  [[ -d "$WEB_DEST" ]] || run install -d -m 0755 "$WEB_DEST"
fi

if [[ -f docs/deployment.md ]]; then
  install_file docs/deployment.md "$DOC_DEST" 0644
fi

# ---- system configuration --------------------------------------------------------
install_file deploy/systemd/bodyscan.service "$UNIT_DEST" 0644
if ((CHANGED)); then RESTART_NEEDED=1; fi
install_file deploy/udev/60-bodyscan.rules "$UDEV_DEST" 0644
install_file deploy/sysctl/60-bodyscan-gige.conf "$SYSCTL_DEST" 0644

# The unit's DeviceAllow=char-ttyUSB is resolved when the service starts; the
# name exists only once the usbserial module is loaded, so load it at boot.
if [[ -f "$MODULES_DEST" ]] && grep -qx usbserial "$MODULES_DEST"; then
  say "unchanged: $MODULES_DEST"
else
  say "writing $MODULES_DEST (load usbserial at boot)"
  if ((DRY_RUN)); then
    printf '  would write: usbserial > %s\n' "$MODULES_DEST"
  else
    printf '%s\n' '# bodyscan: the USB serial bridge driver, so that DeviceAllow=char-ttyUSB' \
      "# in $UNIT_DEST resolves when the service starts" usbserial >"$MODULES_DEST"
    chmod 0644 "$MODULES_DEST"
  fi
fi

# ---- /etc/bodyscan and the data folder -------------------------------------------
# /etc/bodyscan: root writes, the service reads (rig.json, a TLS key if the server
# terminates TLS itself), nobody else looks.
if [[ -d "$CONF_DIR" ]]; then
  say "$CONF_DIR exists"
else
  say "creating $CONF_DIR"
fi
run install -d -m 0750 -o root -g "$SERVICE_USER" "$CONF_DIR"

if [[ -e "$CONF_DIR/rig.json" ]]; then
  say "kept existing $CONF_DIR/rig.json"
elif [[ -f "$EXAMPLE_RIG" ]]; then
  say "creating $CONF_DIR/rig.json from $EXAMPLE_RIG (an example: describe your rig, docs/rig-description.md)"
  run install -m 0640 -o root -g "$SERVICE_USER" "$EXAMPLE_RIG" "$CONF_DIR/rig.json"
else
  warn "$EXAMPLE_RIG not found: write $CONF_DIR/rig.json yourself (docs/rig-description.md)"
fi

# Read by systemd as root before the service starts; holds the first admin
# password, so only root may read it.
write_new_file "$CONF_DIR/bodyscan.env" 0600 root root <<'EOF'
# Environment for bodyscan.service, read by systemd (as root) at every start.
# Keep this file mode 0600 root:root. After editing: systemctl restart bodyscan
#
# The first admin's password. Used only while no admin account exists, i.e. at
# the first start; without it the server prints a generated password once, to the
# journal (journalctl -u bodyscan). Delete the line after the first login.
#BODYSCAN_ADMIN_PASSWORD=change-me-at-first-login
#
# Extra options appended to `bodyscan serve` (docs/deployment.md), e.g. the
# first admin's name, or TLS in the server itself instead of a proxy. To change
# --address or --port, override ExecStart with `systemctl edit bodyscan`.
#BODYSCAN_EXTRA_ARGS=--admin manager
#BODYSCAN_EXTRA_ARGS=--tls-cert /etc/bodyscan/tls/cert.pem --tls-key /etc/bodyscan/tls/key.pem
EOF
if [[ -e "$CONF_DIR/bodyscan.env" ]] &&
  [[ "$(stat -c '%a %U %G' "$CONF_DIR/bodyscan.env")" != "600 root root" ]]; then
  say "fixing the mode of $CONF_DIR/bodyscan.env to 0600 root:root"
  run chown root:root "$CONF_DIR/bodyscan.env"
  run chmod 0600 "$CONF_DIR/bodyscan.env"
fi

# systemd's StateDirectory= also creates it at start; made here so that backups
# and restores have a place to go before the first start.
if [[ -d "$DATA_DIR" ]]; then
  say "$DATA_DIR exists"
else
  say "creating $DATA_DIR"
  run install -d -m 0700 -o "$SERVICE_USER" -g "$SERVICE_USER" "$DATA_DIR"
fi

# ---- reload ----------------------------------------------------------------------
if ((HAVE_UDEVADM)); then
  say "reloading udev rules and re-applying them to USB and serial devices"
  run udevadm control --reload-rules
  run udevadm trigger --action=change --subsystem-match=usb --subsystem-match=tty
else
  warn "udevadm not found (no udev here?): the rules apply from the next boot"
fi

say "applying $SYSCTL_DEST"
if ! run sysctl -q -p "$SYSCTL_DEST"; then
  warn "sysctl could not apply $SYSCTL_DEST (container?); it applies from the next boot"
fi
if ! run modprobe usbserial; then
  warn "could not load usbserial now; it loads at the next boot"
fi

if ((SYSTEMD_RUNNING)); then
  run systemctl daemon-reload
  run systemctl enable bodyscan.service
  if ((START)); then
    if systemctl is-active --quiet bodyscan.service; then
      if ((RESTART_NEEDED)); then
        say "bodyscan is running the previous version. When no scan is in progress:"
        say "  systemctl restart bodyscan"
      else
        say "bodyscan is running"
      fi
    else
      run systemctl start bodyscan.service
      if ((!DRY_RUN)); then
        say "started. Status: systemctl status bodyscan; log: journalctl -u bodyscan -f"
        say "first start: the first admin password is BODYSCAN_ADMIN_PASSWORD from $CONF_DIR/bodyscan.env, or printed once in the log"
      fi
    fi
  fi
else
  warn "systemd is not running here (container or chroot): enabling only"
  run systemctl enable bodyscan.service || warn "could not enable bodyscan.service"
fi
say "done. Next: edit $CONF_DIR/rig.json, put a TLS proxy in front (deploy/proxy/), see docs/deployment.md"
