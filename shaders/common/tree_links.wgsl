// The light tree's shape, shared by the perfect tree and the radix tree (issue 23): the root
// is node 1, leaf k is node `leaves + k` (a node is a leaf iff id >= leaves). The perfect
// tree's inner node i has children 2i, 2i + 1; the radix tree's has tree_links[i] = (left,
// right, first leaf, last leaf). Twin: `base::sst_node::Topology`.
// Contract: the includer declares `tree_links: array<vec4<u32>>` (a dummy for the perfect
// tree) and `fn tree_radix() -> bool` (from its uniforms).

fn tree_left(i: u32) -> u32 {
    if tree_radix() {
        return tree_links[i].x;
    }
    return 2u * i;
}

fn tree_right(i: u32) -> u32 {
    if tree_radix() {
        return tree_links[i].y;
    }
    return 2u * i + 1u;
}

// The leaves (indices) inner node i covers: first, last (inclusive).
fn tree_leaf_range(i: u32, leaves: u32) -> vec2<u32> {
    if tree_radix() {
        return tree_links[i].zw;
    }
    let down = firstLeadingBit(leaves) - firstLeadingBit(i);
    let first = (i << down) - leaves;
    return vec2<u32>(first, first + (1u << down) - 1u);
}

// The leaves (indices) any node n covers, leaves included.
fn tree_node_range(n: u32, leaves: u32) -> vec2<u32> {
    if n >= leaves {
        return vec2<u32>(n - leaves);
    }
    return tree_leaf_range(n, leaves);
}

// Depth of node n (root 0): the perfect tree's level, or down the radix tree's links to the
// child whose leaf range holds n's. Twin: `Topology::depth`.
fn tree_depth(n: u32, leaves: u32) -> u32 {
    if !tree_radix() {
        return firstLeadingBit(n);
    }
    let r = tree_node_range(n, leaves);
    var node = 1u;
    var d = 0u;
    loop {
        if node == n || node >= leaves || d >= 128u {
            break;
        }
        let lr = tree_node_range(tree_left(node), leaves);
        node = select(tree_right(node), tree_left(node), lr.x <= r.x && r.y <= lr.y);
        d += 1u;
    }
    return d;
}
