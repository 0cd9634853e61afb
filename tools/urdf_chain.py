#!/usr/bin/env python3
"""Writes a URDF of an n-link revolute chain hanging under gravity, for timing `mechanica run`.

Each link is a uniform rod of length L and mass m hanging along −z from its joint; the joints
are revolute, their axes alternating between y and x, so q = 0 is the stable equilibrium and
the modes are those of a three-dimensional compound pendulum chain.

Usage: python3 tools/urdf_chain.py N [--length L] [--mass M] > chain.urdf
"""

import argparse


def chain_urdf(n: int, length: float, mass: float) -> str:
    inertia = mass * length * length / 12.0
    thin = 1e-6 * inertia
    lines = ['<?xml version="1.0"?>', f'<robot name="chain_{n}">', '  <link name="base"/>']
    for i in range(n):
        lines += [
            f'  <link name="link{i}">',
            "    <inertial>",
            f'      <origin xyz="0 0 {-0.5 * length!r}" rpy="0 0 0"/>',
            f'      <mass value="{mass!r}"/>',
            f'      <inertia ixx="{inertia!r}" ixy="0" ixz="0" iyy="{inertia!r}" iyz="0" izz="{thin!r}"/>',
            "    </inertial>",
            "  </link>",
        ]
    for i in range(n):
        parent = "base" if i == 0 else f"link{i - 1}"
        drop = 0.0 if i == 0 else -length
        axis = "0 1 0" if i % 2 == 0 else "1 0 0"
        lines += [
            f'  <joint name="joint{i}" type="continuous">',
            f'    <parent link="{parent}"/><child link="link{i}"/>',
            f'    <origin xyz="0 0 {drop!r}" rpy="0 0 0"/><axis xyz="{axis}"/>',
            "  </joint>",
        ]
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int, help="number of links")
    parser.add_argument("--length", type=float, default=0.1, help="link length, m")
    parser.add_argument("--mass", type=float, default=1.0, help="link mass, kg")
    args = parser.parse_args()
    if args.n < 1:
        parser.error("n must be at least 1")
    print(chain_urdf(args.n, args.length, args.mass), end="")


if __name__ == "__main__":
    main()
