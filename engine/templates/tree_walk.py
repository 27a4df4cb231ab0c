"""One walk of an expression's tree for the gate (engine.templates.expressions): every node in
ast.walk's order with its depth and children, from which the gate's checks, the names read and
the parts that read no parameter all come. The gate used to walk each tree seven times and each
candidate part once more; an imported NC program checks every line, so this is done once."""
from __future__ import annotations

import ast
from collections import deque

# Nodes whose evaluation can fail or allocate: a part holding one and reading no parameter is
# evaluated by the gate (a display or f-string of constants alone is bounded by its text).
COMPUTING = (ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp, ast.Call, ast.Subscript)


class ExpressionTree:
    """The nodes of one tree, breadth first (as ast.walk), the children of each, and where each
    node sits in its parent: (parent, field, index in the field's list or None)."""
    __slots__ = ("nodes", "children", "slots")

    def __init__(self, tree: ast.AST, max_depth: int, too_deep: Exception):
        self.nodes: list[ast.AST] = []
        self.children: dict[int, list[ast.AST]] = {}          # id(node) -> its children
        self.slots: dict[int, tuple[ast.AST, str, int | None]] = {}   # id(node) -> where it sits
        pending = deque(((tree, 1),))
        while pending:
            node, depth = pending.popleft()
            if depth > max_depth:
                raise too_deep
            self.nodes.append(node)
            inner = self.children[id(node)] = self._children(node)
            pending.extend((child, depth + 1) for child in inner)

    def _children(self, node: ast.AST) -> list[ast.AST]:
        """ast.iter_child_nodes, as a list, without its generators; each child's slot noted."""
        found, slots = [], self.slots
        for name in node._fields:
            value = getattr(node, name, None)
            if isinstance(value, ast.AST):
                found.append(value)
                slots[id(value)] = (node, name, None)
            elif isinstance(value, list):
                for index, item in enumerate(value):
                    if isinstance(item, ast.AST):
                        found.append(item)
                        slots[id(item)] = (node, name, index)
        return found

    def put(self, node: ast.AST, instead: ast.AST) -> None:
        """`instead` where `node` was in its parent."""
        parent, field, index = self.slots[id(node)]
        if index is None:
            setattr(parent, field, instead)
        else:
            getattr(parent, field)[index] = instead

    def of_type(self, kind):
        return [node for node in self.nodes if isinstance(node, kind)]

    def parts_without(self, reads) -> list[ast.AST]:
        """The largest parts holding a COMPUTING node in which no Name satisfies `reads(name)`
        (below the root Expression)."""
        if not any(isinstance(node, COMPUTING) for node in self.nodes):
            return []
        reading: set[int] = set()     # ids of nodes
        computing: set[int] = set()
        for node in reversed(self.nodes):   # children before their parents
            inner = self.children[id(node)]
            if isinstance(node, ast.Name) and reads(node.id) or not reading.isdisjoint(map(id, inner)):
                reading.add(id(node))
            if isinstance(node, COMPUTING) or not computing.isdisjoint(map(id, inner)):
                computing.add(id(node))
        parts, pending = [], [self.nodes[0]]
        while pending:
            node = pending.pop()
            if id(node) in computing and id(node) not in reading and not isinstance(node, ast.Expression):
                parts.append(node)
            elif id(node) in computing:
                pending.extend(self.children[id(node)])
        return parts
