#!/bin/sh
# Writes a URDF chain of N revolute links (1 kg, 0.5 m) hanging from a fixed base to stdout,
# for scaling checks: sh tools/make-urdf-chain.sh 20000 > chain.urdf (docs/performance.md).
set -eu
awk -v n="${1:?usage: make-urdf-chain.sh N}" 'BEGIN {
  print "<?xml version=\"1.0\"?>\n<robot name=\"chain\">\n<link name=\"base\"/>"
  for (i = 1; i <= n; ++i)
    printf "<link name=\"l%d\"><inertial><origin xyz=\"0 0 -0.25\"/><mass value=\"1\"/>" \
           "<inertia ixx=\"0.021\" iyy=\"0.021\" izz=\"0.0004\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n", i
  for (i = 1; i <= n; ++i)
    printf "<joint name=\"j%d\" type=\"continuous\"><parent link=\"%s\"/><child link=\"l%d\"/>" \
           "<origin xyz=\"0 0 %s\"/><axis xyz=\"0 1 0\"/></joint>\n", i, i == 1 ? "base" : "l" (i - 1), i, i == 1 ? "0" : "-0.5"
  print "</robot>"
}'
