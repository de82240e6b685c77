#!/bin/sh
# Makes everything DDS Security needs for `craneassist sim --input dds` and `craneassist remote`
# (docs/remote-commands.md explains every command below):
#
#   OUTDIR/ca.pem                     the CA certificate (identity CA and permissions CA in one)
#   OUTDIR/ca-private/                the CA's key and its bookkeeping: keep it off the machines
#   OUTDIR/governance.p7s             the domain governance (governance.xml.in), signed by the CA
#   OUTDIR/NAME.pem, NAME.key         identity certificate and private key, for NAME in crane,
#                                     operator, viewer
#   OUTDIR/NAME-permissions.p7s       NAME's permissions (permissions.xml.in), signed by the CA:
#                                     crane and viewer may subscribe to craneassist/operator_command,
#                                     operator may publish it; nothing else
#   OUTDIR/crane.yaml, operator.yaml, viewer.yaml
#                                     DDS settings files (config/telemetry/default.yaml format)
#                                     with commands.enabled and every commands.security file
#
# Usage: make-certs.sh [--ca-name NAME] OUTDIR
#   --ca-name NAME   the CA's common name (default "craneassist CA"); tests make a second,
#                    unrelated CA with another name
# Environment: NOT_BEFORE, NOT_AFTER (YYYY-MM-DD, UTC) bound the certificates and permissions;
# default 2024-01-01 .. 2036-12-31 (in the past, so clock skew between machines does not matter,
# and before 2038, so 32-bit time_t systems read it).
#
# Needs openssl (Debian 12: OpenSSL 3.0). ECDSA keys on P-256 (prime256v1), SHA-256 signatures:
# what Fast DDS's builtin PKI-DH plugin takes (it also takes RSA-2048).
set -eu

ca_name="craneassist CA"
if [ "${1:-}" = "--ca-name" ]; then
  [ $# -ge 2 ] || { echo "make-certs.sh: --ca-name needs a value" >&2; exit 2; }
  ca_name=$2
  shift 2
fi
if [ $# -ne 1 ] || [ -z "$1" ]; then
  echo "usage: make-certs.sh [--ca-name NAME] OUTDIR" >&2
  exit 2
fi
out=$1
here=$(cd "$(dirname "$0")" && pwd)
not_before=${NOT_BEFORE:-2024-01-01}
not_after=${NOT_AFTER:-2036-12-31}
domain_min=0
domain_max=232
organization=craneassist

command -v openssl >/dev/null || { echo "make-certs.sh: openssl not found (apt install openssl)" >&2; exit 3; }
mkdir -p "$out/ca-private/newcerts"
out=$(cd "$out" && pwd)
priv=$out/ca-private
umask 077  # keys readable by their owner only

# openssl ca: a minimal CA (its database under ca-private/) so certificates get explicit
# validity dates (openssl req -x509 and x509 -req start them "now" in OpenSSL 3.0).
: >"$priv/index.txt"
[ -f "$priv/serial" ] || echo 1000 >"$priv/serial"
cat >"$priv/ca.cnf" <<EOF
[ ca ]
default_ca = craneassist_ca
[ craneassist_ca ]
dir = $priv
database = \$dir/index.txt
new_certs_dir = \$dir/newcerts
serial = \$dir/serial
default_md = sha256
policy = any_name
preserve = yes
unique_subject = no
copy_extensions = none
[ any_name ]
organizationName = optional
commonName = supplied
[ ca_cert ]
basicConstraints = critical, CA:true
keyUsage = critical, keyCertSign, cRLSign, digitalSignature
subjectKeyIdentifier = hash
[ identity_cert ]
basicConstraints = critical, CA:false
keyUsage = critical, digitalSignature, keyAgreement
subjectKeyIdentifier = hash
authorityKeyIdentifier = keyid
EOF
start=$(echo "$not_before" | tr -d -)000000Z
end=$(echo "$not_after" | tr -d -)235959Z

# The CA: a P-256 key and a self-signed certificate.
openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$priv/ca.key"
openssl req -new -key "$priv/ca.key" -subj "/O=$organization/CN=$ca_name" -out "$priv/ca.csr"
openssl ca -batch -notext -config "$priv/ca.cnf" -selfsign -keyfile "$priv/ca.key" \
  -extensions ca_cert -startdate "$start" -enddate "$end" -in "$priv/ca.csr" \
  -out "$out/ca.pem" 2>"$priv/ca.log"

# Governance: the template with the domain range, signed (S/MIME, text/plain as Fast DDS reads it).
sed -e "s/@DOMAIN_MIN@/$domain_min/" -e "s/@DOMAIN_MAX@/$domain_max/" \
  "$here/governance.xml.in" >"$out/governance.xml"
openssl smime -sign -text -in "$out/governance.xml" -out "$out/governance.p7s" \
  -signer "$out/ca.pem" -inkey "$priv/ca.key"

# One identity: key, certificate signed by the CA, permissions with its exact subject, signed.
identity() {
  name=$1
  action=$2
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$out/$name.key"
  openssl req -new -key "$out/$name.key" -subj "/O=$organization/CN=$name" -out "$priv/$name.csr"
  openssl ca -batch -notext -config "$priv/ca.cnf" -cert "$out/ca.pem" -keyfile "$priv/ca.key" \
    -extensions identity_cert -startdate "$start" -enddate "$end" -in "$priv/$name.csr" \
    -out "$out/$name.pem" 2>>"$priv/ca.log"
  subject=$(openssl x509 -in "$out/$name.pem" -noout -subject -nameopt RFC2253 | sed 's/^subject=//')
  sed -e "s/@NAME@/$name/" -e "s|@SUBJECT@|$subject|" -e "s/@ACTION@/$action/g" \
    -e "s/@NOT_BEFORE@/${not_before}T00:00:00/" -e "s/@NOT_AFTER@/${not_after}T23:59:59/" \
    -e "s/@DOMAIN_MIN@/$domain_min/" -e "s/@DOMAIN_MAX@/$domain_max/" \
    "$here/permissions.xml.in" >"$out/$name-permissions.xml"
  openssl smime -sign -text -in "$out/$name-permissions.xml" -out "$out/$name-permissions.p7s" \
    -signer "$out/ca.pem" -inkey "$priv/ca.key"
  cat >"$out/$name.yaml" <<EOF
# DDS settings of the '$name' identity, made by tools/dds-security/make-certs.sh
# (docs/remote-commands.md). Paths are relative to this file.
format: craneassist-telemetry/1
domain_id: 0
commands:
  enabled: true
  security:
    identity_ca: ca.pem
    identity_certificate: $name.pem
    private_key: $name.key
    permissions_ca: ca.pem
    governance: governance.p7s
    permissions: $name-permissions.p7s
EOF
}

identity crane subscribe
identity operator publish
identity viewer subscribe

# Certificates, governance and permissions are public; only the keys are secret.
chmod 644 "$out"/*.pem "$out"/*.p7s "$out"/*.xml "$out"/*.yaml
echo "make-certs.sh: CA '$ca_name', identities crane, operator, viewer in $out (valid $not_before .. $not_after)"
