"""flexible.chain_ordered: the joints of an expanded document along the chain, from the end of the file's first
joint, whatever order the expansion appended them in."""

from clearsim.model.flexible import chain_ordered


def joint(name: str, first: str, second: str) -> dict:
    return {"name": name, "type": "revolute", "bodies": [first, second]}


def test_joints_appended_out_of_order_come_back_along_the_chain():
    """ground -a- p -b- q -c- r -d- s, with c and b appended last (as a split link's slide or a beam's hinges)."""
    joints = [joint("a", "ground", "p"), joint("d", "r", "s"), joint("c", "q", "r"), joint("b", "p", "q")]
    assert [j["name"] for j in chain_ordered(joints)] == ["a", "b", "c", "d"]


def test_the_chain_is_numbered_from_the_end_of_the_file_s_first_joint():
    """Each joint at its bodies' highest number: a (p alone) ties with b (p, q), and keeps its place before b."""
    joints = [joint("d", "r", "s"), joint("a", "ground", "p"), joint("c", "q", "r"), joint("b", "p", "q")]
    assert [j["name"] for j in chain_ordered(joints)] == ["d", "c", "a", "b"]


def test_no_bodies_no_reordering():
    grounded = [joint("x", "ground", "ground")]
    assert chain_ordered([]) == [] and chain_ordered(grounded) == grounded
