#!/usr/bin/env python3
"""Writes FEBio 4 input decks (.feb, format 4.0) of the problems of bench/febio/README.md, on
the meshes adhesim builds for the same scenario files.

  feb.py pad --n 9 --mu 0 OUT.feb             problem 1: bench/febio/pad.toml
  feb.py blocks --n 9 --m 8 --mu 0.3 OUT.feb  problem 2: bench/febio/blocks.toml
  feb.py hertz --msh MESH.msh --mu 0 --depth 2e-6 --increments 2 OUT.feb
                                              problem 3: bench/febio/hertz.toml

The pad: a box [0, width] x [0, height] x [0, width] [m] cut into n x layers x n hex8
elements (adhesim's `block` generator: the node coordinates are the same numbers), FEBio's
neo-Hookean (the same strain energy as adhesim's `neo-hookean`). Its top face is held in x
and z and pushed down by `depth` along a linear load curve in `increments` equal time steps.

- mu = 0: the bottom face against the plane y = 0 as a `rigid_wall` surface constraint with
  the augmented Lagrangian (FEBio's frictionless rigid plane).
- mu > 0: the bottom face is the primary surface of a `sliding-elastic` contact with Coulomb
  friction whose secondary surface is the top face of a plate below the pad, one hex8 element
  with all its nodes fixed (FEBio has no frictional analytic plane).

The contact force is read as the reaction at the pad's top nodes (a logfile of Ry per node
and time step), the same quantity as adhesim's `pad.top.Fy` column of history.csv.
"""

import argparse
import sys
from pathlib import Path


def block_mesh(n, layers, size, offset=(0.0, 0.0, 0.0), first=1):
    """Nodes [(x, y, z)], hex8 connectivity, bottom faces (outward −y), top faces (outward
    +y) and top node ids of adhesim's `block` generator: the box `size` = (Lx, Ly, Lz) [m]
    at `offset`, cut into n x layers x n elements, node ids from `first`. Node (i, j, k),
    with i along x, j along y (0 = bottom) and k along z, has id first + i + (n+1)(k + (n+1) j)
    and the coordinates offset + size * (i/n, j/layers, k/n), the numbers adhesim computes.
    Each element lists its face z = k first, counter-clockwise seen from +z (positive
    volume, FEBio's hex8 ordering)."""
    def node_id(i, j, k):
        return first + i + (n + 1) * (k + (n + 1) * j)

    (lx, ly, lz), (ox, oy, oz) = size, offset
    nodes = [(ox + lx * (i / n), oy + ly * (j / layers), oz + lz * (k / n))
             for j in range(layers + 1) for k in range(n + 1) for i in range(n + 1)]
    corners = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
               (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    elements = [[node_id(i + a, j + b, k + c) for a, b, c in corners]
                for j in range(layers) for k in range(n) for i in range(n)]
    bottom = [[node_id(i, 0, k), node_id(i + 1, 0, k), node_id(i + 1, 0, k + 1),
               node_id(i, 0, k + 1)] for k in range(n) for i in range(n)]
    top = [[node_id(i, layers, k), node_id(i, layers, k + 1), node_id(i + 1, layers, k + 1),
            node_id(i + 1, layers, k)] for k in range(n) for i in range(n)]
    top_nodes = [node_id(i, layers, k) for k in range(n + 1) for i in range(n + 1)]
    return nodes, elements, bottom, top, top_nodes


def pad_mesh(n, layers, width, height):
    """The pad of bench/febio/pad.toml: nodes, elements, bottom faces and top node ids."""
    nodes, elements, bottom, _, top_nodes = block_mesh(n, layers, (width, height, width))
    return nodes, elements, bottom, top_nodes


def plate_mesh(first_id, width, thickness):
    """A square plate under the pad, 1.5 width wide around it, its top face on y = 0: eight
    nodes from `first_id`, one hex8 element and its top face (outward normal +y)."""
    lo, hi = -0.25 * width, 1.25 * width
    nodes = [(x, y, z) for y in (-thickness, 0.0) for z in (lo, hi) for x in (lo, hi)]
    ids = [first_id + i for i in range(8)]
    # corner (x, y, z) index = ix + 2 iz + 4 iy
    element = [ids[0], ids[1], ids[5], ids[4], ids[2], ids[3], ids[7], ids[6]]
    top_face = [ids[4], ids[6], ids[7], ids[5]]
    return nodes, element, top_face


def num(x):
    return repr(float(x))


def xml_nodes(name, nodes, first_id=1):
    rows = "".join(f'<node id="{first_id + i}">{num(x)},{num(y)},{num(z)}</node>\n'
                   for i, (x, y, z) in enumerate(nodes))
    return f'<Nodes name="{name}">\n{rows}</Nodes>\n'


def xml_elements(name, elements, first_id=1):
    rows = "".join(f'<elem id="{first_id + i}">{",".join(map(str, e))}</elem>\n'
                   for i, e in enumerate(elements))
    return f'<Elements type="hex8" name="{name}">\n{rows}</Elements>\n'


def xml_surface(name, faces):
    rows = "".join(f'<quad4 id="{i + 1}">{",".join(map(str, f))}</quad4>\n'
                   for i, f in enumerate(faces))
    return f'<Surface name="{name}">\n{rows}</Surface>\n'


def xml_node_set(name, ids):
    return f'<NodeSet name="{name}">{",".join(map(str, ids))}</NodeSet>\n'


def control(increments, symmetric):
    """Quasi-static, fixed steps, FEBio's default quasi-Newton (BFGS) solver and tolerances;
    a non-symmetric stiffness where friction makes it so."""
    kind = "symmetric" if symmetric else "non-symmetric"
    return (f'<Control><analysis>STATIC</analysis><time_steps>{increments}</time_steps>'
            f'<step_size>{1.0 / increments!r}</step_size>'
            f'<solver type="solid"><symmetric_stiffness>{kind}</symmetric_stiffness>'
            '</solver></Control>\n')


def material(young, poisson):
    return ('<Material><material id="1" name="rubber" type="neo-Hookean">'
            f'<density>1000</density><E>{num(young)}</E><v>{num(poisson)}</v>'
            '</material></Material>\n')


def frictionless_wall():
    """The plane y = 0 (FEBio's plane a x + b y + c z = d with (a, b, c, d) = (0, 1, 0, 0))."""
    return ('<Constraints><constraint type="rigid_wall" surface="bottom">'
            '<laugon>AUGLAG</laugon><tolerance>0.01</tolerance><penalty>1e12</penalty>'
            '<plane>0,1,0,0</plane><offset>0</offset></constraint></Constraints>\n')


def frictional_contact(mu, pair, penalty):
    """FEBio's sliding-elastic contact of the surface pair `pair` with Coulomb friction `mu`
    (0: frictionless): the augmented Lagrangian on FEBio's automatic penalty scaled by
    `penalty`. On the pad against the plate 10 (with the penalty method alone, factors 1 and
    10 leave the force 27 % and 3.7 % low at 100 contact nodes, and 50 does not converge); on
    the pad against the soft block 1 (10 stalls in the first step's line searches)."""
    return (f'<Contact><contact type="sliding-elastic" surface_pair="{pair}">'
            f'<laugon>AUGLAG</laugon><penalty>{penalty}</penalty><auto_penalty>1</auto_penalty>'
            f'<fric_coeff>{num(mu)}</fric_coeff><two_pass>0</two_pass>'
            '<symmetric_stiffness>0</symmetric_stiffness><search_tol>0.01</search_tol>'
            '<tolerance>0.01</tolerance></contact></Contact>\n')


def pad_deck(a):
    """Problem 1: the pad on a rigid plane (rigid_wall without friction, a fixed plate with
    sliding-elastic and friction)."""
    nodes, elements, bottom, top = pad_mesh(a.n, a.layers, a.width, a.height)
    mesh = xml_nodes("pad", nodes) + xml_elements("pad", elements)
    mesh += xml_surface("bottom", bottom) + xml_node_set("top", top)
    domains = '<SolidDomain name="pad" mat="rubber"/>'
    boundary = push_top(a.depth)
    if a.mu > 0.0:
        p_nodes, p_element, p_top = plate_mesh(len(nodes) + 1, a.width, a.height / a.layers)
        mesh += xml_nodes("plate", p_nodes, len(nodes) + 1)
        mesh += xml_elements("plate", [p_element], len(elements) + 1)
        mesh += xml_surface("plate_top", [p_top])
        mesh += xml_node_set("plate_nodes", [len(nodes) + 1 + i for i in range(8)])
        mesh += ('<SurfacePair name="pad-on-plate"><primary>bottom</primary>'
                 '<secondary>plate_top</secondary></SurfacePair>\n')
        domains += '<SolidDomain name="plate" mat="rubber"/>'
        boundary += ('<bc name="plate" node_set="plate_nodes" type="zero displacement">'
                     '<x_dof>1</x_dof><y_dof>1</y_dof><z_dof>1</z_dof></bc>')
        interaction = frictional_contact(a.mu, "pad-on-plate", 10)
    else:
        interaction = frictionless_wall()
    return deck(a, mesh, domains, boundary, interaction)


def blocks_deck(a):
    """Problem 2: the pad (n x layers x n) on a base block (m x layers x m, 1 mm wider than
    the pad on each side), both neo-Hookean, the base's bottom held."""
    w, h = a.width, a.height
    pad_nodes, pad_elements, pad_bottom, _, pad_top = block_mesh(
        a.n, a.layers, (w, h, w), (0.001, h, 0.001))
    first = len(pad_nodes) + 1
    base_nodes, base_elements, _, base_top, _ = block_mesh(
        a.m, a.layers, (w + 0.002, h, w + 0.002), first=first)
    mesh = xml_nodes("pad", pad_nodes) + xml_nodes("base", base_nodes, first)
    mesh += xml_elements("pad", pad_elements)
    mesh += xml_elements("base", base_elements, len(pad_elements) + 1)
    mesh += xml_surface("pad_bottom", pad_bottom) + xml_surface("base_top", base_top)
    mesh += xml_node_set("top", pad_top)
    mesh += xml_node_set("base_bottom", range(first, first + (a.m + 1) ** 2))
    mesh += ('<SurfacePair name="pad-on-base"><primary>pad_bottom</primary>'
             '<secondary>base_top</secondary></SurfacePair>\n')
    domains = '<SolidDomain name="pad" mat="rubber"/><SolidDomain name="base" mat="rubber"/>'
    boundary = (push_top(a.depth) + '<bc name="base" node_set="base_bottom" '
                'type="zero displacement"><x_dof>1</x_dof><y_dof>1</y_dof><z_dof>1</z_dof></bc>')
    return deck(a, mesh, domains, boundary, frictional_contact(a.mu, "pad-on-base", 1))


def push_top(depth):
    """The pad's top held in x and z and pushed down by `depth` [m] along load curve 1."""
    return ('<bc name="hold" node_set="top" type="zero displacement">'
            '<x_dof>1</x_dof><y_dof>0</y_dof><z_dof>1</z_dof></bc>'
            '<bc name="push" node_set="top" type="prescribed displacement"><dof>y</dof>'
            f'<value lc="1">{num(-depth)}</value><relative>0</relative></bc>')


def deck(a, mesh, domains, boundary, interaction):
    """The whole .feb: control, material, mesh, boundary conditions, the contact
    `interaction`, the linear load curve and the logfile of Ry at the node set `top`."""
    return ('<?xml version="1.0" encoding="ISO-8859-1"?>\n<febio_spec version="4.0">\n'
            '<Module type="solid"/>\n' + control(a.increments, a.mu == 0.0)
            + material(a.young, a.poisson)
            + f'<Mesh>\n{mesh}</Mesh>\n<MeshDomains>{domains}</MeshDomains>\n'
            + f'<Boundary>{boundary}</Boundary>\n' + interaction
            + '<LoadData><load_controller id="1" type="loadcurve"><interpolate>LINEAR'
            '</interpolate><points><pt>0,0</pt><pt>1,1</pt></points></load_controller>'
            '</LoadData>\n<Output><logfile><node_data data="Ry" node_set="top" '
            'file="top_reaction.txt" delim=","/></logfile></Output>\n</febio_spec>\n')


def read_msh(path):
    """Nodes {tag: (x, y, z)}, and per element type the elements [(physical tags, node
    tags)] of a Gmsh 4.1 ASCII file (what adhesim reads as ASCII)."""
    lines = iter(Path(path).read_text().split("\n"))
    physical = {}   # (dim, entity tag) -> [physical tags]
    nodes, elements = {}, {}
    for line in lines:
        if line == "$Entities":
            counts = [int(c) for c in next(lines).split()]
            for dim, count in enumerate(counts):
                for _ in range(count):
                    f = next(lines).split()
                    at = 4 if dim == 0 else 7
                    physical[(dim, int(f[0]))] = [int(t) for t in f[at + 1:at + 1 + int(f[at])]]
        elif line == "$Nodes":
            blocks = int(next(lines).split()[0])
            for _ in range(blocks):
                _, _, _, count = (int(c) for c in next(lines).split())
                tags = [int(next(lines)) for _ in range(count)]
                for tag in tags:
                    nodes[tag] = tuple(float(c) for c in next(lines).split())
        elif line == "$Elements":
            blocks = int(next(lines).split()[0])
            for _ in range(blocks):
                dim, entity, kind, count = (int(c) for c in next(lines).split())
                tags = physical.get((dim, entity), [])
                rows = elements.setdefault(kind, [])
                for _ in range(count):
                    rows.append((tags, [int(c) for c in next(lines).split()[1:]]))
    return nodes, elements


def physical_names(path):
    """{name: (dim, tag)} of a Gmsh file's $PhysicalNames."""
    text = Path(path).read_text()
    block = text.split("$PhysicalNames\n", 1)[1].split("$EndPhysicalNames", 1)[0]
    names = {}
    for row in block.strip().split("\n")[1:]:
        dim, tag, name = row.split(maxsplit=2)
        names[name.strip('"')] = (int(dim), int(tag))
    return names


def outward(tri, tets_by_face, coords):
    """`tri` (three node ids) ordered so that its normal points out of the tetrahedron it
    bounds."""
    tet = tets_by_face[tuple(sorted(tri))]
    (opposite,) = set(tet) - set(tri)
    a, b, c, o = (coords[i] for i in (*tri, opposite))
    ab = [b[k] - a[k] for k in range(3)]
    ac = [c[k] - a[k] for k in range(3)]
    n = [ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
         ab[0] * ac[1] - ab[1] * ac[0]]
    ao = [o[k] - a[k] for k in range(3)]
    return tri if sum(n[k] * ao[k] for k in range(3)) < 0.0 else [tri[0], tri[2], tri[1]]


def hertz_deck(a):
    """Problem 3: the quarter hemisphere of a Gmsh tet4 mesh (physical surfaces top, sym_x,
    sym_z, curved; lengths in mm, scaled by 1e-3) pressed by its top onto the rigid plane
    y = 0, frictionless (rigid_wall)."""
    raw_nodes, elements = read_msh(a.msh)
    names = physical_names(a.msh)
    ids = {tag: i + 1 for i, tag in enumerate(sorted(raw_nodes))}
    coords = {ids[t]: tuple(1e-3 * c for c in xyz) for t, xyz in raw_nodes.items()}
    tets = [[ids[t] for t in nodes] for _, nodes in elements[4]]
    tets_by_face = {tuple(sorted(f)): tet for tet in tets
                    for f in ([tet[0], tet[1], tet[2]], [tet[0], tet[1], tet[3]],
                              [tet[0], tet[2], tet[3]], [tet[1], tet[2], tet[3]])}

    def faces(name):
        tag = names[name][1]
        return [outward([ids[t] for t in nodes], tets_by_face, coords)
                for tags, nodes in elements[2] if tag in tags]

    def node_set(name):
        return sorted({i for f in faces(name) for i in f})

    rows = "".join(f'<node id="{i}">{num(x)},{num(y)},{num(z)}</node>\n'
                   for i, (x, y, z) in sorted(coords.items()))
    mesh = f'<Nodes name="cap">\n{rows}</Nodes>\n<Elements type="tet4" name="cap">\n'
    mesh += "".join(f'<elem id="{i + 1}">{",".join(map(str, t))}</elem>\n'
                    for i, t in enumerate(tets)) + "</Elements>\n"
    mesh += "".join(f'<tri3 id="{i + 1}">{",".join(map(str, f))}</tri3>\n'
                    for i, f in enumerate(faces("curved"))).join(
                        ['<Surface name="bottom">\n', '</Surface>\n'])
    for name in ("top", "sym_x", "sym_z"):
        mesh += xml_node_set(name, node_set(name))
    boundary = push_top(a.depth)
    boundary += ('<bc name="sym_x" node_set="sym_x" type="zero displacement"><x_dof>1</x_dof>'
                 '<y_dof>0</y_dof><z_dof>0</z_dof></bc><bc name="sym_z" node_set="sym_z" '
                 'type="zero displacement"><x_dof>0</x_dof><y_dof>0</y_dof><z_dof>1</z_dof></bc>')
    return deck(a, mesh, '<SolidDomain name="cap" mat="rubber"/>', boundary,
                frictionless_wall())


def common_arguments(p, n):
    p.add_argument("--n", type=int, default=n)
    p.add_argument("--layers", type=int, default=4)
    p.add_argument("--width", type=float, default=0.01)
    p.add_argument("--height", type=float, default=0.002)
    p.add_argument("--depth", type=float, default=1e-4)
    p.add_argument("--young", type=float, default=2.6e6)
    p.add_argument("--poisson", type=float, default=0.3)
    p.add_argument("--mu", type=float, default=0.3)
    p.add_argument("--increments", type=int, default=5)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="problem", required=True)
    pad = sub.add_parser("pad", help="problem 1: the pad of bench/febio/pad.toml")
    common_arguments(pad, 9)
    pad.add_argument("out")
    blocks = sub.add_parser("blocks", help="problem 2: bench/febio/blocks.toml")
    common_arguments(blocks, 9)
    blocks.add_argument("--m", type=int, default=8)
    blocks.add_argument("out")
    hertz = sub.add_parser("hertz", help="problem 3: bench/febio/hertz.toml")
    common_arguments(hertz, 0)
    hertz.add_argument("--msh", required=True)
    hertz.add_argument("out")
    a = p.parse_args(argv)
    with open(a.out, "w") as f:
        f.write({"pad": pad_deck, "blocks": blocks_deck, "hertz": hertz_deck}[a.problem](a))
    return 0


if __name__ == "__main__":
    sys.exit(main())
