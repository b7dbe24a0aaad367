<?xml version="1.0" encoding="UTF-8"?>
<tileset version="1.10" tiledversion="1.10.2" name="dungeon" tilewidth="32" tileheight="32" tilecount="3" columns="3">
 <image source="dungeon.png" width="96" height="32"/>
 <tile id="1" type="wall"/>
 <tile id="2" class="guard"/>
</tileset>
