#!/usr/bin/env bash
# The test command's lavapipe (scripts/test.sh): Mesa's from bookworm-backports on Debian 12.
# Debian 12's own Mesa (22.3) compiles a shader's every storage-buffer access with a scattered
# address into a loop over the SIMD lanes, one bounds-checked scalar load or store at a time; Mesa
# 25 (bookworm-backports) uses the CPU's gathers. The Vulkan tests run about three times faster
# (examples/scenes/cloth.json on the 2-core CI machine: 86 -> 312 steps a second, the same state
# hash), which is what keeps CI's Vulkan runs on lavapipe within its time.
# Installs mesa-vulkan-drivers from bookworm-backports (adding that Debian source when no source
# lists it) when this is Debian 12, run as root, and the installed Mesa is older than 25. Anything
# else (another system, not root, no network) prints why and leaves the system's Mesa: the tests
# run on it, only slower. MOTES_LAVAPIPE_BACKPORT=0 in scripts/test.sh skips this script.
set -euo pipefail
note() { echo "lavapipe: $*"; }
codename=$(. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}")
if [ "$codename" != bookworm ]; then
  note "not Debian 12 (${codename:-unknown}): the system's Mesa is used"
  exit 0
fi
installed=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
if [ -n "$installed" ] && dpkg --compare-versions "$installed" ge 25; then
  note "Mesa $installed"
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  note "Mesa ${installed:-not installed}; Mesa 25 from bookworm-backports needs root" \
    "(apt-get install -t bookworm-backports mesa-vulkan-drivers): the Vulkan tests run slower"
  exit 0
fi
export DEBIAN_FRONTEND=noninteractive
if ! grep -rqsE '^[^#]*bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
  echo "deb http://deb.debian.org/debian bookworm-backports main" \
    >/etc/apt/sources.list.d/motes-bookworm-backports.list
  note "added /etc/apt/sources.list.d/motes-bookworm-backports.list"
fi
if apt-get update -qq && apt-get install -y -qq --no-install-recommends -t bookworm-backports \
  mesa-vulkan-drivers >/dev/null; then
  note "Mesa $(dpkg-query -W -f='${Version}' mesa-vulkan-drivers) from bookworm-backports"
else
  note "could not install Mesa from bookworm-backports (above): the Vulkan tests run on" \
    "Mesa ${installed:-from scripts/setup.sh}, slower"
fi
